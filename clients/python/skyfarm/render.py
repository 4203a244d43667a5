"""A render on the farm: its status, its events, its images, cancelling it.

``Client.submit`` answers a ``Render``; ``Client.get_render(id)`` makes one for
an existing id.  ``wait`` follows ``GET /v1/renders/{id}/events`` (Server-
Sent Events, each frame's data the status document): a dropped connection
is resumed with ``Last-Event-ID`` so no event is lost or repeated, and a
stream the server refuses (503: every event-stream slot taken) falls back
to polling the status.
"""

import json
import os
import socket
import time
from http.client import HTTPException

from .errors import RenderFailed, ServerError, TransportError
from .sse import iter_events
from .waiting import TERMINAL_STATES, Deadline, Reconnects, progress_callback

# The server sends ": keepalive" every 10 s (by default) on a quiet stream:
# a read that waits much longer than that means the connection is dead.
_STREAM_READ_TIMEOUT_S = 45.0


def image_format(path, format=None):
    """``exr`` or ``png``: ``format`` if given, else from the file name
    (``.png`` is PNG, anything else EXR)."""
    if format is None:
        format = "png" if os.fspath(path).lower().endswith(".png") else "exr"
    format = format.lower().lstrip(".")
    if format not in ("exr", "png"):
        raise ValueError("format must be 'exr' or 'png', not %r" % format)
    return format


class Render:
    """A render's handle: ``id``; from a submission also ``created``,
    ``from_cache`` and ``answer`` (the whole 202 body)."""

    def __init__(self, client, id, answer=None):
        self.client = client
        self.id = id
        self.answer = answer or {}

    def __repr__(self):
        return "Render(%r)" % self.id

    @property
    def created(self):
        return self.answer.get("created")

    @property
    def from_cache(self):
        return self.answer.get("from_cache")

    @property
    def path(self):
        return "/v1/renders/" + self.id

    def status(self):
        """The status document (state, progress, error estimate, plan, ...)."""
        return self.client._transport.json("GET", self.path)

    def cancel(self, purge=False):
        """Cancel (the status document afterwards), or with ``purge`` delete
        the render's files and record (None)."""
        if purge:
            self.client._transport.call("DELETE", self.path, {"purge": True})
            return None
        return self.client._transport.json("DELETE", self.path)

    def image(self, format="exr"):
        """The current image's bytes (progressive until done)."""
        return self.client._transport.call("GET", self.path + "/image." + image_format("", format)).body

    def download(self, path, format=None):
        """Write the current image (progressive until done) to ``path``; the
        format is ``exr`` or ``png``, by default from the name.  Returns the
        path.  ``Conflict`` (409) before the first pass covers the frame."""
        return self.client._transport.download(self.path + "/image." + image_format(path, format), path)

    def events(self, last_event_id=None):
        """The raw event stream: (event type, status document) pairs as they
        come, until a terminal event or the stream's end.  No resumption:
        ``wait`` does that."""
        answer = self.client._transport.open("GET", self.path + "/events",
                                             headers=self._event_headers(last_event_id),
                                             timeout=_STREAM_READ_TIMEOUT_S, busy_wait=False)
        with answer:
            for event in iter_events(answer, last_event_id):
                yield event.event, json.loads(event.data)
                if event.event in TERMINAL_STATES:
                    return

    def wait(self, progress=None, timeout=None, poll_interval=0.5, raise_on_failure=True):
        """Block until the render is done, failed or cancelled; the final
        status document.

        progress: None, True (a bar on stderr) or a callable given each
        status document as it changes.  timeout: seconds (``WaitTimeout``
        beyond).  A failed or cancelled render raises ``RenderFailed``
        unless ``raise_on_failure`` is false.
        """
        callback, own_bar = progress_callback(progress)
        deadline = Deadline(timeout)
        try:
            status = self._follow_events(callback, deadline)
            if status is None:  # the server refused the stream
                status = self._poll(callback, deadline, poll_interval)
        finally:
            if own_bar is not None:
                own_bar.close()
        if raise_on_failure and status.get("state") in ("failed", "cancelled"):
            reason = status.get("failure") or ""
            raise RenderFailed("render %s %s%s" % (self.id, status.get("state"), ": " + reason if reason else ""),
                               status.get("state"), status)
        return status

    @staticmethod
    def _event_headers(last_event_id):
        headers = {"Accept": "text/event-stream", "Cache-Control": "no-cache"}
        if last_event_id is not None:
            headers["Last-Event-ID"] = str(last_event_id)
        return headers

    def _follow_events(self, callback, deadline):
        """The final status from the event stream, or None when the server
        refuses streams (503)."""
        transport = self.client._transport
        last_id = None
        reconnects = Reconnects()
        while True:
            deadline.check("render " + self.id)
            try:
                answer = transport.open("GET", self.path + "/events", headers=self._event_headers(last_id),
                                        timeout=deadline.cap(_STREAM_READ_TIMEOUT_S), busy_wait=False)
            except ServerError as e:
                if e.status == 503:
                    return None
                raise
            except TransportError as e:
                reconnects.failed(e, deadline)
                continue
            try:
                with answer:
                    for event in iter_events(answer, last_id):
                        last_id = event.id
                        reconnects.ok()
                        try:
                            status = json.loads(event.data)
                        except ValueError:
                            continue  # not ours to judge; the next event or the status will do
                        callback(status)
                        if event.event in TERMINAL_STATES:
                            return status
            except (socket.timeout, OSError, HTTPException) as e:
                # Dropped mid-stream: resume after the last event received.
                deadline.check("render " + self.id)
                reconnects.failed(TransportError("event stream of render %s: %s" % (self.id, e)), deadline)
                continue
            # The stream ended without a terminal event: the render is over
            # and its events were trimmed, or a proxy cut it.  The status says.
            try:
                status = self.status()
            except TransportError as e:
                reconnects.failed(e, deadline)
                continue
            if status.get("state") in TERMINAL_STATES:
                callback(status)
                return status
            reconnects.failed(TransportError("event stream of render %s ended early" % self.id), deadline)

    def _poll(self, callback, deadline, poll_interval):
        reconnects = Reconnects()
        previous = None
        while True:
            try:
                status = self.status()
                reconnects.ok()
            except TransportError as e:
                deadline.check("render " + self.id)
                reconnects.failed(e, deadline)
                continue
            seen = (status.get("state"), json.dumps(status.get("progress"), sort_keys=True),
                    json.dumps(status.get("error"), sort_keys=True))
            if seen != previous:
                callback(status)
                previous = seen
            if status.get("state") in TERMINAL_STATES:
                return status
            deadline.check("render " + self.id)
            time.sleep(deadline.cap(poll_interval))
