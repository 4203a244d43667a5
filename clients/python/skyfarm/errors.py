"""The client's exceptions.

Every error the server answers is an RFC 9457 problem document
(``application/problem+json``: type, title, status, detail, and for invalid
input ``errors[]`` naming each field); it is raised as a ``SkyfarmError``
subclass chosen by the HTTP status, carrying the document's parts.  Errors
that never reached the server (connection refused, a timeout) are
``TransportError``; a render that ended failed or cancelled while waited for
is ``RenderFailed``.
"""

import json
from collections import namedtuple

# One invalid field, parameter or header of a 400 problem: ``field`` is the
# body path (``camera.width``) or the parameter's name (``view_zenith``,
# ``Idempotency-Key``); ``message`` says what is wrong without the field's
# name (``must be an integer in [1, 16384], got -3``).
FieldError = namedtuple("FieldError", ["field", "message"])


class SkyfarmError(Exception):
    """Base of every error this package raises.

    ``status`` is the HTTP status (None when the server was not reached),
    ``title`` and ``detail`` the problem's, ``errors`` a list of
    ``FieldError(field, message)`` and ``problem`` the whole document.
    """

    def __init__(self, message, status=None, title=None, detail=None, errors=None, problem=None,
                 retry_after=None):
        super().__init__(message)
        self.status = status
        self.title = title
        self.detail = detail
        self.errors = list(errors or [])
        self.problem = problem or {}
        self.retry_after = retry_after

    @property
    def fields(self):
        """The names of the invalid fields, in the server's order."""
        return [e.field for e in self.errors]

    @property
    def type(self):
        """The problem's type URI (``urn:skyfarm:problem:...``), or None."""
        return self.problem.get("type")


class TransportError(SkyfarmError):
    """The server could not be reached, or the connection broke."""


class ProblemError(SkyfarmError):
    """An HTTP error answer of the server (4xx, 5xx)."""


class ValidationError(ProblemError):
    """400: the request, a query parameter or a header is invalid."""


class Unauthorized(ProblemError):
    """401: the server needs a bearer token (``--token``) or this one is wrong."""


class NotFound(ProblemError):
    """404: no such render, timelapse, asset or route."""


class Conflict(ProblemError):
    """409: not possible now (an image not ready yet, a frame not purged alone)."""


class Gone(ProblemError):
    """410: the render's files were deleted after the server's retention time."""


class ContentTooLarge(ProblemError):
    """413: the body is larger than the server accepts."""


class Unprocessable(ProblemError):
    """422: an Idempotency-Key reused with another body, or an unusable asset file."""


class TooManyRequests(ProblemError):
    """429: the farm is at capacity; ``retry_after`` says when to try again."""


class ServerError(ProblemError):
    """5xx: the server failed, or is overloaded (503), or out of disk (507)."""


class RenderFailed(SkyfarmError):
    """A render or timelapse ended ``failed`` or ``cancelled`` while waited for.

    ``state`` is the final state and ``document`` the final status document.
    """

    def __init__(self, message, state, document):
        super().__init__(message)
        self.state = state
        self.document = document


class WaitTimeout(SkyfarmError, TimeoutError):
    """``wait(timeout=...)`` ran out before the render ended."""


_BY_STATUS = {400: ValidationError, 401: Unauthorized, 404: NotFound, 409: Conflict, 410: Gone,
              413: ContentTooLarge, 422: Unprocessable, 429: TooManyRequests}


def _field_error(entry):
    field = str(entry.get("field", ""))
    message = entry.get("message")
    if not isinstance(message, str):
        rule = str(entry.get("rule", "invalid"))
        value = entry.get("value")
        message = rule + (", got " + str(value) if value else "")
    else:
        # The server's message is "<field or (request)>: <rule>[, got <value>]".
        for prefix in (field + ": ", "(request): "):
            if message.startswith(prefix):
                message = message[len(prefix):]
                break
    return FieldError(field, message)


def problem_error(status, body, content_type="", retry_after=None):
    """The exception for an error answer: its status, body bytes and type.

    A body that is not a problem document (a proxy's HTML page, say) still
    gives an error with the status and the body's start as the detail.
    """
    problem = {}
    if body:
        try:
            parsed = json.loads(body.decode("utf-8", "replace"))
            if isinstance(parsed, dict):
                problem = parsed
        except ValueError:
            pass
    title = problem.get("title") if isinstance(problem.get("title"), str) else None
    detail = problem.get("detail") if isinstance(problem.get("detail"), str) else None
    if not problem and body:
        detail = body[:200].decode("utf-8", "replace").strip()
    entries = problem.get("errors") if isinstance(problem.get("errors"), list) else []
    errors = [_field_error(e) for e in entries if isinstance(e, dict)]
    if errors:
        # One line per field, each naming it: "camera.fov_deg: must be ..."
        message = "; ".join((e.field or "(request)") + ": " + e.message for e in errors)
    else:
        message = "HTTP %d %s" % (status, title or "")
        if detail and detail != title:
            message = message.rstrip() + ": " + detail
    cls = _BY_STATUS.get(status, ServerError if status >= 500 else ProblemError)
    return cls(message.strip(), status=status, title=title, detail=detail, errors=errors, problem=problem,
               retry_after=retry_after)
