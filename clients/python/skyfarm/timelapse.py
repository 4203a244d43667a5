"""A timelapse on the farm: many renders of one camera over a time range.

``Client.timelapse(request)`` answers a ``Timelapse``.  It has no event
stream, so ``wait`` polls ``GET /v1/timelapses/{id}``; when it is done the
frames (EXR, and PNGs exposed for the whole sequence), the contact sheet and
the video (when the server has ffmpeg) can be downloaded.
"""

import os
import time

from .errors import NotFound, RenderFailed, TransportError
from .render import Render, image_format
from .waiting import TERMINAL_STATES, Deadline, Reconnects, progress_callback


class Timelapse:
    """A timelapse's handle: ``id``; from a submission also ``answer``."""

    def __init__(self, client, id, answer=None):
        self.client = client
        self.id = id
        self.answer = answer or {}

    def __repr__(self):
        return "Timelapse(%r)" % self.id

    @property
    def path(self):
        return "/v1/timelapses/" + self.id

    def status(self):
        """The status document: state, stage, progress, each frame, video."""
        return self.client._transport.json("GET", self.path)

    def frames(self):
        """The frames: index, time, render_id, state, progress, ..."""
        return self.client._transport.json("GET", self.path + "/frames")["frames"]

    def frame_render(self, n):
        """Frame n's ``Render`` (None until the frame is queued)."""
        render_id = self.frames()[n].get("render_id")
        return Render(self.client, render_id) if render_id else None

    def cancel(self):
        """Cancel every frame; the status document."""
        return self.client._transport.json("DELETE", self.path)

    def wait(self, progress=None, timeout=None, poll_interval=1.0, raise_on_failure=True):
        """Block until the timelapse is done (frames, contact sheet and video
        made), failed or cancelled; its final status document.  The
        arguments are those of ``Render.wait``."""
        callback, own_bar = progress_callback(progress)
        deadline = Deadline(timeout)
        reconnects = Reconnects()
        previous = None
        try:
            while True:
                try:
                    status = self.status()
                    reconnects.ok()
                except TransportError as e:
                    deadline.check("timelapse " + self.id)
                    reconnects.failed(e, deadline)
                    continue
                seen = (status.get("state"), status.get("stage"), repr(status.get("progress")))
                if seen != previous:
                    callback(status)
                    previous = seen
                if status.get("state") in TERMINAL_STATES:
                    break
                deadline.check("timelapse " + self.id)
                time.sleep(deadline.cap(poll_interval))
        finally:
            if own_bar is not None:
                own_bar.close()
        if raise_on_failure and status.get("state") in ("failed", "cancelled"):
            reason = status.get("failure") or ""
            raise RenderFailed("timelapse %s %s%s" % (self.id, status.get("state"), ": " + reason if reason else ""),
                               status.get("state"), status)
        return status

    def download_frame(self, n, path, format=None):
        """Frame n as EXR or PNG (by default from the name); the path."""
        return self.client._transport.download("%s/frames/%d.%s" % (self.path, n, image_format(path, format)), path)

    def download_contact_sheet(self, path):
        """The contact sheet PNG (once done); the path."""
        return self.client._transport.download(self.path + "/contact_sheet.png", path)

    def download_video(self, path):
        """The H.264 MP4 (once done; ``NotFound`` when the server made none,
        ``problem`` says why); the path."""
        return self.client._transport.download(self.path + "/video.mp4", path)

    def download(self, folder, exr=True, png=True, contact_sheet=True, video=True):
        """Everything of a done timelapse into ``folder``: ``frame_0000.exr``
        and ``.png`` per frame, ``contact_sheet.png``, ``video.mp4`` (left out
        when the server has none).  The paths written, in that order."""
        os.makedirs(folder, exist_ok=True)
        written = []
        count = len(self.frames())
        width = max(4, len(str(count - 1)))
        for n in range(count):
            for wanted, ext in ((exr, "exr"), (png, "png")):
                if wanted:
                    name = "frame_%0*d.%s" % (width, n, ext)
                    written.append(self.download_frame(n, os.path.join(folder, name)))
        if contact_sheet:
            written.append(self.download_contact_sheet(os.path.join(folder, "contact_sheet.png")))
        if video:
            try:
                written.append(self.download_video(os.path.join(folder, "video.mp4")))
            except NotFound:
                pass  # no ffmpeg on the server: the status's video.reason says so
        return written
