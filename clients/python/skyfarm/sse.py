"""Server-Sent Events: frames of a ``text/event-stream``.

The parsing rules of the HTML Living Standard, section 9.2.6 ("Interpreting
an event stream"): lines end in CR LF, LF or CR; a line starting with ``:``
is a comment (the server's ``: keepalive``); ``field: value`` loses one space
after the colon; ``data`` lines of one event are joined with LF; ``id`` sets
the last event id (kept across events, and ignored when it contains NUL);
a blank line dispatches the event, with the type ``message`` when no
``event`` line came.  An event without data is not dispatched.
"""

from collections import namedtuple

# One dispatched event: ``id`` is the last event id at that point (a string,
# or None when the stream never sent one), ``event`` its type, ``data`` the
# joined data lines.
Event = namedtuple("Event", ["id", "event", "data"])


class EventParser:
    """Feed it lines (bytes or str, with or without their line ending);
    ``feed`` returns the event a blank line completes, else None."""

    def __init__(self, last_event_id=None):
        self.last_event_id = last_event_id
        self._type = ""
        self._data = []

    def feed(self, line):
        if isinstance(line, bytes):
            line = line.decode("utf-8", "replace")
        line = line.rstrip("\r\n")
        if line == "":
            return self._dispatch()
        if line.startswith(":"):
            return None
        name, colon, value = line.partition(":")
        if colon and value.startswith(" "):
            value = value[1:]
        if name == "event":
            self._type = value
        elif name == "data":
            self._data.append(value)
        elif name == "id":
            if "\0" not in value:
                self.last_event_id = value
        # "retry" (a reconnection delay) and unknown fields are ignored.
        return None

    def _dispatch(self):
        if not self._data:
            self._type = ""
            return None
        event = Event(self.last_event_id, self._type or "message", "\n".join(self._data))
        self._type = ""
        self._data = []
        return event


def iter_events(stream, last_event_id=None):
    """The events of a binary file-like ``stream`` read line by line, until
    it ends.  A CR alone as a line ending (allowed, never sent by skyfarm)
    is handled within a read line."""
    parser = EventParser(last_event_id)
    for raw in iter(stream.readline, b""):
        # readline splits on LF only; a lone CR inside is a line break too.
        pieces = raw.replace(b"\r\n", b"\n").split(b"\r")
        if pieces[-1] == b"":
            pieces.pop()  # the read ended with a CR: no line follows it yet
        for piece in pieces:
            event = parser.feed(piece)
            if event is not None:
                yield event
