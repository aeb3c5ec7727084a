"""The monitor page's own files (``/`` and ``/static/...``), served from memory.

Starlette's :class:`~starlette.staticfiles.StaticFiles` is the documented fallback;
:func:`page_files` gives one or the other. Both answer ``get_response(path, scope)`` with the
same bytes and media types (``tests/monitor/test_static.py`` checks it), an ETag that a reload
revalidates (``304``), ``Cache-Control: no-cache`` (a page from an older monitor is never run
from the browser's cache) and ``404`` for anything else, paths outside the folder included.

**Why not StaticFiles alone.** StaticFiles stats, opens, reads and closes each file on worker
threads, four or so thread hops a file. In a process that also runs CPU-bound Python (``cyborg
up`` runs the simulator, the tree runner and the detector beside the monitor), each hop waits
for the GIL, and the page's eight files arrive later. Measured on the 2-core benchmark machine,
under load from other jobs (docs/benchmarks.md, "Web monitor"): with one CPU-bound thread
beside the server, a page load (``/`` and its 7 files, 6 connections) took
p50 23-30 ms from memory and 43-54 ms with StaticFiles (server CPU 16-19 ms against 45-51 ms);
in ``benchmarks/monitor_web.py``'s first-paint measurement, alternating page by page between
two monitors of one tree, the last file arrived at a median of 101 ms against 165 ms and the
tree was drawn at 394 ms against 465 ms. The goal is 300 ms and the reference run drew it at
273 ms, so StaticFiles alone would lose the goal. The page is small (about 75 kB) and fixed
while the monitor runs, so holding it in memory costs nothing worth having.

**When to fall back.** ``page_files(from_memory=False)`` (or ``create_app(...,
files=PageFiles(directory=...))``) serves the folder as it is on disk at each request, with
Range requests and Last-Modified: use it while editing the page's files, or if the page ever
grows large.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path
from typing import Protocol

from starlette.datastructures import Headers
from starlette.responses import PlainTextResponse, Response
from starlette.staticfiles import StaticFiles
from starlette.types import Scope

STATIC = Path(__file__).with_name("static")

MEDIA_TYPES = {".html": "text/html; charset=utf-8", ".css": "text/css; charset=utf-8",
               ".js": "text/javascript; charset=utf-8", ".mjs": "text/javascript; charset=utf-8",
               ".LICENSE": "text/plain; charset=utf-8"}
"""The page's own kinds of file, with their media types fixed here rather than taken from the
platform's table (which, on some Windows machines, calls ``.js`` ``text/plain``, and a browser
then refuses to run the page's modules)."""


class PageSource(Protocol):
    """What the server asks of the page's files."""

    async def get_response(self, path: str, scope: Scope) -> Response:
        """The answer to a request for ``path`` (relative to the folder), on the event loop."""
        ...


class PageCache:
    """The page's files, read once and served from memory with an ETag (the default)."""

    def __init__(self, folder: Path = STATIC) -> None:
        self.files: dict[str, tuple[bytes, str, str]] = {}
        for path in sorted(folder.rglob("*")):
            if path.is_file() and path.suffix in MEDIA_TYPES:
                content = path.read_bytes()
                etag = '"' + hashlib.sha1(content, usedforsecurity=False).hexdigest()[:16] + '"'
                self.files[path.relative_to(folder).as_posix()] = (
                    content, MEDIA_TYPES[path.suffix], etag)

    async def get_response(self, path: str, scope: Scope) -> Response:
        """The file at ``path``: ``304`` when the request has its ETag, ``404`` when unknown."""
        found = self.files.get(path)
        if found is None:
            return PlainTextResponse(f"no such file: {path}", 404)
        content, media_type, etag = found
        headers = {"ETag": etag, "Cache-Control": "no-cache"}
        if Headers(scope=scope).get("if-none-match") == etag:
            return Response(status_code=304, headers=headers)
        return Response(content, media_type=media_type, headers=headers)


class PageFiles(StaticFiles):
    """The fallback: Starlette's StaticFiles, always revalidated, with :data:`MEDIA_TYPES`.

    StaticFiles brings ETag and Last-Modified, ``HEAD`` and ranges, and nothing outside the
    folder.
    """

    def file_response(self, full_path: str | os.PathLike[str], stat_result: os.stat_result,
                      scope: Scope, status_code: int = 200) -> Response:
        """StaticFiles' response, marked ``no-cache`` and typed by :data:`MEDIA_TYPES`."""
        response = super().file_response(full_path, stat_result, scope, status_code)
        response.headers["Cache-Control"] = "no-cache"
        media_type = MEDIA_TYPES.get(Path(full_path).suffix)
        if media_type is not None and response.status_code != 304:
            response.headers["Content-Type"] = media_type
        return response


def page_files(folder: Path = STATIC, *, from_memory: bool = True) -> PageSource:
    """The page's files in ``folder``, from memory (:class:`PageCache`) by default.

    With ``from_memory=False`` they come from disk through Starlette's StaticFiles
    (:class:`PageFiles`).
    """
    return PageCache(folder) if from_memory else PageFiles(directory=folder)
