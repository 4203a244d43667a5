"""The farm's API as Python calls.

Parameters (``Client(url=None, token=None, timeout=60, busy_wait_s=0)``):
  url      the server, ``http://127.0.0.1:8080`` by default, else the
           environment's ``SKYFARM_URL``; a path prefix (a proxy's) is kept
  token    the bearer token of a server run with ``--token``; default the
           environment's ``SKYFARM_TOKEN``
  timeout  seconds one HTTP exchange may wait for the server (a path-traced
           probe gets at least 180: the server waits up to its
           ``--probe-timeout``, 120 s by default)
  busy_wait_s  how long to keep retrying a request the server refuses for
           now with Retry-After (429 farm at capacity, 503 no probe
           workers), as it says; 0 (default): raise ``TooManyRequests`` /
           ``ServerError`` at once

Every route of api/openapi.yaml has a method; requests and query
parameters pass through as given (a dict, or a JSON file's path), so new
request fields and query parameters need no change here.  Answers are the
server's JSON as dicts; errors raise ``skyfarm.SkyfarmError`` subclasses.
"""

import json
import os

from .render import Render
from .timelapse import Timelapse
from .transport import Transport, json_default

DEFAULT_URL = "http://127.0.0.1:8080"
_PROBE_TIMEOUT_S = 180.0


def request_body(request):
    """The JSON body of a request given as a dict (serialised; datetimes as
    ISO 8601), bytes or a
    str of JSON text (sent as they are), or a file's path (its bytes, so the
    server's errors speak of the file as written)."""
    if isinstance(request, dict):
        return json.dumps(request, default=json_default).encode("utf-8")
    if isinstance(request, bytes):
        return request
    if isinstance(request, str) and request.lstrip().startswith("{"):
        return request.encode("utf-8")
    if isinstance(request, (str, os.PathLike)):
        with open(request, "rb") as f:
            return f.read()
    raise TypeError("a request is a dict, JSON text or bytes, or a JSON file's path, not %s" % type(request).__name__)


class Page(list):
    """One page of a listing: a list of status documents, with the server's
    ``offset``, ``limit`` and ``total``."""

    def __init__(self, items, offset, limit, total):
        super().__init__(items)
        self.offset = offset
        self.limit = limit
        self.total = total


class Assets:
    """``client.assets``: mesh (OBJ, PLY, STL, glTF, GLB) and cloud volume
    (OpenVDB) uploads.  The server has no route to list or delete assets:
    an asset is named by the SHA-256 of its canonical file and kept."""

    def __init__(self, transport):
        self._transport = transport

    def upload(self, data, format=None, grid=None):
        """Upload a file (a path, or its bytes); the asset's metadata
        (``id``: ``sha256:...``, triangles or voxels, bounds).  ``format``:
        obj, ply, stl, gltf, glb, vdb (default: the server detects it);
        ``grid``: an OpenVDB file's float grid."""
        if isinstance(data, (str, os.PathLike)):
            with open(data, "rb") as f:
                data = f.read()
        return self._transport.json("POST", "/v1/assets", {"format": format, "grid": grid}, data,
                                    {"Content-Type": "application/octet-stream"})

    def get(self, asset_id):
        """An asset's metadata."""
        return self._transport.json("GET", "/v1/assets/" + asset_id)

    def download(self, asset_id, path):
        """The asset's canonical file (SKYMESH1 for a mesh, SKYVOL1 for a
        volume) into ``path``; the path."""
        kind = "volume" if self.get(asset_id).get("kind") == "volume" else "mesh"
        return self._transport.download("/v1/assets/%s/%s" % (asset_id, kind), path)


class Client:
    def __init__(self, url=None, token=None, timeout=60.0, busy_wait_s=0.0):
        url = url or os.environ.get("SKYFARM_URL") or DEFAULT_URL
        token = token if token is not None else (os.environ.get("SKYFARM_TOKEN") or None)
        self._transport = Transport(url, token, timeout, busy_wait_s)
        self.assets = Assets(self._transport)

    @property
    def url(self):
        return self._transport.url

    def __repr__(self):
        return "Client(%r)" % self.url

    # --- renders ----------------------------------------------------------

    def submit(self, request, idempotency_key=None):
        """POST /v1/renders: a ``Render`` (``created``, ``from_cache``).
        ``request``: a dict, JSON text or a JSON file's path.  The same
        ``idempotency_key`` with the same body answers the same render, so a
        retry after a lost answer is safe."""
        headers = {"Idempotency-Key": idempotency_key} if idempotency_key else None
        answer = self._transport.json("POST", "/v1/renders", None, request_body(request), headers)
        return Render(self, answer["id"], answer)

    def get_render(self, render_id):
        """The ``Render`` of an existing id (no request is made)."""
        return Render(self, render_id)

    def renders(self, offset=0, limit=20):
        """GET /v1/renders: one page of status documents, newest first."""
        page = self._transport.json("GET", "/v1/renders", {"offset": offset, "limit": limit})
        return Page(page["renders"], page["offset"], page["limit"], page["total"])

    # --- timelapses -------------------------------------------------------

    def timelapse(self, request, idempotency_key=None):
        """POST /v1/timelapses: a ``Timelapse``.  ``request`` as for
        ``submit`` (with ``start``, ``end``, ``step_s`` or ``frames``)."""
        headers = {"Idempotency-Key": idempotency_key} if idempotency_key else None
        answer = self._transport.json("POST", "/v1/timelapses", None, request_body(request), headers)
        return Timelapse(self, answer["id"], answer)

    def get_timelapse(self, timelapse_id):
        """The ``Timelapse`` of an existing id (no request is made)."""
        return Timelapse(self, timelapse_id)

    def timelapses(self, offset=0, limit=20):
        """GET /v1/timelapses: one page of status documents, newest first."""
        page = self._transport.json("GET", "/v1/timelapses", {"offset": offset, "limit": limit})
        return Page(page["timelapses"], page["offset"], page["limit"], page["total"])

    # --- the sky ----------------------------------------------------------

    def sky(self, lat=None, lon=None, time=None, view_zenith=None, view_azimuth=None, **query):
        """GET /v1/sky: radiance in one direction from a cached LUT sky
        (spectral, XYZ, linear sRGB).  Other query parameters (altitude,
        sun_zenith, sun_azimuth, preset, aod, ...) go by keyword."""
        query.update(lat=lat, lon=lon, time=time, view_zenith=view_zenith, view_azimuth=view_azimuth)
        return self._transport.json("GET", "/v1/sky", query)

    def envmap(self, path=None, **query):
        """GET /v1/sky/envmap.exr: a lat-long environment map (lat, lon,
        time or sun_zenith and sun_azimuth, width, sun, ... by keyword).
        Written to ``path`` (returned), or its bytes when ``path`` is None."""
        if path is None:
            return self._transport.call("GET", "/v1/sky/envmap.exr", query).body
        return self._transport.download("/v1/sky/envmap.exr", path, query)

    def probe(self, request):
        """POST /v1/sky/radiance: spectral radiance in given directions
        (``"method": "path"`` on the farm with standard errors, or ``"lut"``)."""
        timeout = max(self._transport.timeout, _PROBE_TIMEOUT_S)
        return self._transport.json("POST", "/v1/sky/radiance", None, request_body(request), timeout=timeout)

    # --- the farm ---------------------------------------------------------

    def workers(self):
        """GET /v1/workers: the connected workers."""
        return self._transport.json("GET", "/v1/workers")["workers"]

    def health(self):
        """GET /healthz: True when the server answers (never needs the token)."""
        return self._transport.json("GET", "/healthz").get("status") == "ok"

    def openapi(self):
        """GET /v1/openapi.yaml: the API document's text."""
        return self._transport.call("GET", "/v1/openapi.yaml").body.decode("utf-8")

    def metrics(self):
        """GET /metrics: the Prometheus text."""
        return self._transport.call("GET", "/metrics").body.decode("utf-8")
