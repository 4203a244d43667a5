"""What waiting on the farm shares: the terminal states, a deadline, the
pauses between tries to reach the server, and the progress argument.

A connection that broke is tried again after a pause that doubles from
0.25 s to 4 s; a wait gives up (``TransportError``) after 60 s without
reaching the server.  The farm survives a restart of its server (its jobs
are in SQLite), so a client may well ride one out.
"""

import time

from .errors import WaitTimeout
from .progress import ProgressBar

TERMINAL_STATES = ("done", "failed", "cancelled")

_RECONNECT_FOR_S = 60.0
_FIRST_PAUSE_S = 0.25
_LONGEST_PAUSE_S = 4.0


def progress_callback(progress):
    """The callable for ``wait(progress=...)`` and the bar made for it (to
    close), if any.  None: nothing; True: a ``ProgressBar`` on stderr; a
    callable: itself, given each status document."""
    if progress is None or progress is False:
        return (lambda status: None), None
    if progress is True:
        bar = ProgressBar()
        return bar, bar
    if not callable(progress):
        raise TypeError("progress must be None, True or a callable taking the status document")
    return progress, None


class Deadline:
    """``timeout`` seconds from now (None: never)."""

    def __init__(self, timeout):
        self.end = None if timeout is None else time.monotonic() + timeout

    def left(self):
        return None if self.end is None else self.end - time.monotonic()

    def check(self, what):
        """``WaitTimeout`` once the deadline has passed."""
        if self.end is not None and time.monotonic() >= self.end:
            raise WaitTimeout("%s did not end within the timeout (it goes on on the server)" % what)

    def cap(self, seconds):
        """``seconds``, or what is left of the deadline if that is less."""
        left = self.left()
        return seconds if left is None else max(0.01, min(seconds, left))


class Reconnects:
    """Pauses between tries to reach the server, and when to give up."""

    def __init__(self):
        self.failing_since = None
        self.pause = _FIRST_PAUSE_S

    def ok(self):
        self.failing_since = None
        self.pause = _FIRST_PAUSE_S

    def failed(self, error, deadline):
        """Sleep before the next try; raise ``error`` after 60 s of failures."""
        now = time.monotonic()
        if self.failing_since is None:
            self.failing_since = now
        if now - self.failing_since > _RECONNECT_FOR_S:
            raise error
        time.sleep(deadline.cap(self.pause))
        self.pause = min(self.pause * 2, _LONGEST_PAUSE_S)
