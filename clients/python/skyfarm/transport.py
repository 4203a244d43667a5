"""HTTP for the client: urllib, a bearer token, problems raised as exceptions.

One ``Transport`` per client: the base URL (a path prefix is kept, for a
server behind a proxy), the token, the default timeout.  Every answer that
is not 2xx becomes the ``SkyfarmError`` subclass of its status
(``errors.problem_error``); a connection that fails becomes
``TransportError``.  Downloads stream into a temporary file beside the
target and are renamed into place, so a broken transfer never leaves a
truncated image under the asked name.
"""

import datetime
import json
import os
import socket
import tempfile
import time
import urllib.error
import urllib.parse
import urllib.request
from http.client import HTTPException

from . import __version__
from .errors import ProblemError, TransportError, problem_error

_CHUNK = 1 << 16


def json_default(value):
    """JSON for what ``json`` cannot write: a datetime is ISO 8601 (the
    server wants a UTC offset: give it an aware datetime)."""
    if isinstance(value, (datetime.datetime, datetime.date)):
        return value.isoformat()
    raise TypeError("%s is not JSON serialisable" % type(value).__name__)


def query_string(query):
    """``?a=1&b=true`` of a dict; None values are left out, booleans are
    ``true``/``false``, datetimes ISO 8601, lists repeat the name.  ``+``
    (a time's UTC offset) is sent as ``%2B``."""
    pairs = []
    for name, value in (query or {}).items():
        values = value if isinstance(value, (list, tuple)) else [value]
        for v in values:
            if v is None:
                continue
            if isinstance(v, bool):
                v = "true" if v else "false"
            elif isinstance(v, (datetime.datetime, datetime.date)):
                v = v.isoformat()
            pairs.append((name, str(v)))
    return "?" + urllib.parse.urlencode(pairs) if pairs else ""


class Response:
    """A finished answer: ``status``, ``headers`` (an email.message.Message)
    and ``body`` (bytes)."""

    def __init__(self, status, headers, body):
        self.status = status
        self.headers = headers
        self.body = body

    def json(self):
        return json.loads(self.body.decode("utf-8")) if self.body else None


class Transport:
    """``busy_wait_s``: how long to keep trying a request the server refuses
    for now with a ``Retry-After`` (429: the farm is at capacity; 503: no
    workers for a probe, or every connection taken), waiting as it says
    between tries; 0: raise at once.  Such a refusal changed nothing on the
    server, so trying again is safe for every method."""

    def __init__(self, url, token=None, timeout=60.0, busy_wait_s=0.0):
        if "://" not in url:
            url = "http://" + url
        self.url = url.rstrip("/")
        self.token = token
        self.timeout = timeout
        self.busy_wait_s = busy_wait_s
        # The environment's http_proxy applies, except to this machine: no
        # proxy can reach our loopback, and CI machines often set one.
        host = urllib.parse.urlsplit(self.url).hostname or ""
        loopback = host in ("localhost", "::1") or host.startswith("127.")
        self._opener = urllib.request.build_opener(*([urllib.request.ProxyHandler({})] if loopback else []))

    def _request(self, method, path, query=None, body=None, headers=None):
        all_headers = {"User-Agent": "skyfarm-python/" + __version__, "Accept": "*/*"}
        if self.token:
            all_headers["Authorization"] = "Bearer " + self.token
        all_headers.update(headers or {})
        return urllib.request.Request(self.url + path + query_string(query), data=body, method=method,
                                      headers=all_headers)

    def open(self, method, path, query=None, body=None, headers=None, timeout=None, busy_wait=True):
        """The open answer of a 2xx (a file-like http.client.HTTPResponse);
        the caller closes it.  ``busy_wait``: False to raise a 429 or 503 at
        once whatever ``busy_wait_s`` says (the event stream polls instead)."""
        start = time.monotonic()
        while True:
            try:
                return self._open_once(method, path, query, body, headers, timeout)
            except ProblemError as e:
                if not busy_wait or e.status not in (429, 503) or e.retry_after is None:
                    raise
                pause = max(e.retry_after, 0.05)
                if time.monotonic() + pause - start > self.busy_wait_s:
                    raise
                time.sleep(pause)

    def _open_once(self, method, path, query, body, headers, timeout):
        request = self._request(method, path, query, body, headers)
        try:
            return self._opener.open(request, timeout=timeout or self.timeout)
        except urllib.error.HTTPError as e:
            try:
                data = e.read()
            except (OSError, HTTPException):
                data = b""
            retry_after = e.headers.get("Retry-After") if e.headers else None
            try:
                retry_after = float(retry_after) if retry_after is not None else None
            except ValueError:
                retry_after = None
            raise problem_error(e.code, data, e.headers.get("Content-Type", "") if e.headers else "",
                                retry_after) from None
        except urllib.error.URLError as e:
            raise TransportError("cannot reach %s: %s" % (self.url, e.reason)) from None
        except (socket.timeout, OSError, HTTPException) as e:
            raise TransportError("%s %s%s: %s" % (method, self.url, path, e)) from None

    def call(self, method, path, query=None, body=None, headers=None, timeout=None):
        """The whole answer of a request as a ``Response``."""
        with self.open(method, path, query, body, headers, timeout) as answer:
            try:
                data = answer.read()
            except (socket.timeout, OSError, HTTPException) as e:
                raise TransportError("%s %s%s: %s" % (method, self.url, path, e)) from None
            return Response(answer.status, answer.headers, data)

    def json(self, method, path, query=None, document=None, headers=None, timeout=None):
        """A JSON request (``document``: a dict, or bytes sent as they are)
        answered with JSON."""
        body = None
        all_headers = dict(headers or {})
        if document is not None:
            if not isinstance(document, bytes):
                document = json.dumps(document, default=json_default).encode("utf-8")
            body = document
            all_headers["Content-Type"] = "application/json"
        return self.call(method, path, query, body, all_headers, timeout).json()

    def download(self, path, target, query=None, timeout=None):
        """GET ``path`` into the file ``target`` (written whole or not at
        all); returns ``target``."""
        target = os.fspath(target)
        folder = os.path.dirname(os.path.abspath(target))
        os.makedirs(folder, exist_ok=True)
        with self.open("GET", path, query, timeout=timeout) as answer:
            fd, partial = tempfile.mkstemp(prefix=".skyfarm-", dir=folder)
            try:
                with os.fdopen(fd, "wb") as out:
                    while True:
                        chunk = answer.read(_CHUNK)
                        if not chunk:
                            break
                        out.write(chunk)
                os.chmod(partial, 0o644)
                os.replace(partial, target)
            except (socket.timeout, OSError, HTTPException) as e:
                os.unlink(partial)
                raise TransportError("GET %s%s: %s" % (self.url, path, e)) from None
            except BaseException:
                os.unlink(partial)
                raise
        return target
