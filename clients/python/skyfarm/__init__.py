"""skyfarm: a client for the skyfarm render farm's HTTP API.

    import skyfarm
    farm = skyfarm.Client("http://127.0.0.1:8080")
    render = farm.submit({"camera": {"projection": "fisheye", "width": 64, "height": 64},
                          "sun": {"zenith_deg": 30, "azimuth_deg": 180}})
    render.wait(progress=True)
    render.download("sky.exr")

Standard library only (Python >= 3.9).  The CLI is ``skyfarm`` (or
``python3 -m skyfarm``); see ``skyfarm --help``.
"""

__version__ = "0.1.0"

from .client import Assets, Client, Page  # noqa: E402
from .errors import (  # noqa: E402
    Conflict, ContentTooLarge, FieldError, Gone, NotFound, ProblemError, RenderFailed, ServerError, SkyfarmError,
    TooManyRequests, TransportError, Unauthorized, Unprocessable, ValidationError, WaitTimeout)
from .progress import ProgressBar  # noqa: E402
from .render import Render  # noqa: E402
from .timelapse import Timelapse  # noqa: E402

__all__ = ["Client", "Render", "Timelapse", "Assets", "Page", "ProgressBar", "SkyfarmError", "TransportError",
           "ProblemError", "ValidationError", "Unauthorized", "NotFound", "Conflict", "Gone", "ContentTooLarge",
           "Unprocessable", "TooManyRequests", "ServerError", "RenderFailed", "WaitTimeout", "FieldError"]
