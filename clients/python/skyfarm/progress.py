"""A one-line progress bar for renders and timelapses, on stderr.

Parameters (``ProgressBar(stream=sys.stderr, width=24, label=None)``):
  stream  where it writes; on a terminal the line is redrawn in place (CR),
          elsewhere (a CI log, a file) a line is written when the state
          changes, every 10 % of progress, and at the end
  width   characters of the bar itself
  label   what the line starts with (default: the document's id)

Call it with each status document (``GET /v1/renders/{id}`` or
``/v1/timelapses/{id}``, or an event's data); ``close()`` ends the line.  A
render's line shows the fraction, the samples per pixel every pixel has,
the estimated relative RMS error of the image as it falls
(``error.estimated_relative_rms``, absent before the first pass has two
samples per pixel and for LUT renders) and the ETA; a timelapse's shows its
frames done.
"""

import sys


def _number(value):
    return value if isinstance(value, (int, float)) and not isinstance(value, bool) else None


def describe(status):
    """The words after the bar: ``16 spp  error 2.17 %  eta 12 s`` for a
    render, ``3/13 frames`` for a timelapse."""
    progress = status.get("progress") or {}
    parts = []
    if "frames_total" in progress:
        parts.append("%s/%s frames" % (progress.get("frames_done", 0), progress.get("frames_total")))
        if status.get("stage") == "making_outputs":
            parts.append("making the outputs")
    else:
        spp = _number(progress.get("samples_per_pixel"))
        if spp is not None and status.get("method") != "lut":  # one look-up per pixel, no samples
            parts.append(("%g spp" % spp))
        error = _number((status.get("error") or {}).get("estimated_relative_rms"))
        if error is not None:
            parts.append("error %.3g %%" % (100.0 * error))
    eta = _number(status.get("eta_s"))
    if eta is not None and status.get("state") in ("queued", "running"):
        parts.append("eta %.0f s" % eta)
    return "  ".join(parts)


class ProgressBar:
    def __init__(self, stream=None, width=24, label=None):
        self.stream = stream if stream is not None else sys.stderr
        self.width = width
        self.label = label
        self.updates = 0
        self._tty = hasattr(self.stream, "isatty") and self.stream.isatty()
        self._last_line = None
        self._last_state = None
        self._last_decile = -1
        self._open = False

    def line(self, status):
        fraction = _number((status.get("progress") or {}).get("fraction")) or 0.0
        fraction = min(max(fraction, 0.0), 1.0)
        filled = int(round(fraction * self.width))
        label = self.label or status.get("id", "")
        bar = "#" * filled + "-" * (self.width - filled)
        text = "%s %-9s [%s] %5.1f %%" % (label, status.get("state", "?"), bar, 100.0 * fraction)
        words = describe(status)
        return text + ("  " + words if words else "")

    def __call__(self, status):
        self.updates += 1
        text = self.line(status)
        if self._tty:
            pad = max(0, len(self._last_line or "") - len(text))
            self.stream.write("\r" + text + " " * pad)
            self._open = True
        else:
            fraction = _number((status.get("progress") or {}).get("fraction")) or 0.0
            decile = int(fraction * 10)
            state = status.get("state")
            if state != self._last_state or decile > self._last_decile:
                self.stream.write(text + "\n")
                self._last_decile = decile
            self._last_state = state
        self._last_line = text
        self.stream.flush()

    def close(self):
        if self._open:
            self.stream.write("\n")
            self.stream.flush()
            self._open = False
