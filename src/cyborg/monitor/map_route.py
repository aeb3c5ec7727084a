"""``GET /api/map/{key}``: a robot's map blob (:mod:`cyborg.monitor.map_store`) for the page.

A key names one blob for good (it is the blob's own hash), so the answer is cached as
immutable: ``Cache-Control: public, max-age=31536000, immutable`` and ``ETag: "<key>"``; a
request with a matching ``If-None-Match`` gets ``304``. The blob goes gzipped
(``Content-Encoding: gzip``) to clients that accept it, plain to others; an unknown key gets
``404``. Like every route it is behind the server's host guard.
"""

from __future__ import annotations

import gzip
import re
from collections.abc import Awaitable, Callable

from starlette.requests import Request
from starlette.responses import JSONResponse, Response

from cyborg.monitor.map_store import MapStore
from cyborg.monitor.off_loop import in_thread

CACHE_CONTROL = "public, max-age=31536000, immutable"
MEDIA_TYPE = "application/octet-stream"
_KEY = re.compile(r"^[0-9a-f]{32}$")


def accepts_gzip(header: str | None) -> bool:
    """Whether an ``Accept-Encoding`` header accepts gzip (not with ``q=0``)."""
    for part in (header or "").lower().split(","):
        coding, *parameters = part.split(";")
        if coding.strip() not in ("gzip", "x-gzip", "*"):
            continue
        for parameter in parameters:
            name, _, value = parameter.partition("=")
            if name.strip() == "q":
                try:
                    return float(value) > 0
                except ValueError:
                    return False
        return True
    return False


def matches_etag(header: str | None, etag: str) -> bool:
    """Whether an ``If-None-Match`` header names ``etag`` (weak or strong) or is ``*``."""
    for part in (header or "").split(","):
        tag = part.strip().removeprefix("W/")
        if tag in (etag, "*"):
            return True
    return False


def map_endpoint(store: MapStore) -> Callable[[Request], Awaitable[Response]]:
    """The route's handler, serving the maps of ``store``."""

    async def serve_map(request: Request) -> Response:
        key = str(request.path_params.get("key", ""))
        stored = store.get(key) if _KEY.match(key) else None
        if stored is None:
            return JSONResponse({"error": "no such map: a robot's map_ref names the maps "
                                          "the monitor has"}, 404)
        etag = f'"{stored.key}"'
        headers = {"Cache-Control": CACHE_CONTROL, "ETag": etag, "Vary": "Accept-Encoding",
                   "X-Content-Type-Options": "nosniff"}
        if matches_etag(request.headers.get("if-none-match"), etag):
            return Response(status_code=304, headers=headers)
        store.fetches += 1
        if accepts_gzip(request.headers.get("accept-encoding")):
            return Response(stored.gzipped, media_type=MEDIA_TYPE,
                            headers={**headers, "Content-Encoding": "gzip"})
        blob = await in_thread(gzip.decompress, stored.gzipped)
        return Response(blob, media_type=MEDIA_TYPE, headers=headers)

    return serve_map
