"""The monitor's web application (Starlette): the page, its WebSocket, exports, health.

==============================  ===============================================================
route                           what
==============================  ===============================================================
``GET /``                       the page (plain ES modules from ``/static``, no build step)
``GET /static/...``             its scripts, styles and the vendored d3-hierarchy
``WS /ws``                      live updates and commands (:mod:`cyborg.monitor.commands`)
``GET /api/robots``             the trees the monitor follows, as JSON
``POST /api/export``            ``{"ns", "format": dot|svg|png, "collapsed": [ids]}`` → file
``GET /stats``                  counters, for health checks and benchmarks
==============================  ===============================================================

WebSocket connections must come from the page itself: a browser that opened some other site
cannot connect (the ``Origin`` must match the ``Host``), so no web page can drive the robot
through a user's browser.
"""

from __future__ import annotations

import asyncio
import contextlib
import hashlib
import json
import logging
from collections.abc import AsyncIterator
from pathlib import Path
from urllib.parse import urlsplit

from starlette.applications import Starlette
from starlette.requests import Request
from starlette.responses import JSONResponse, PlainTextResponse, Response
from starlette.routing import Route, WebSocketRoute
from starlette.websockets import WebSocket, WebSocketDisconnect

from cyborg.monitor.client import RESYNC, Client
from cyborg.monitor.commands import CommandError, handle
from cyborg.monitor.export import ExportError, render, view_dot
from cyborg.monitor.hub import Hub

log = logging.getLogger("cyborg.monitor")

STATIC = Path(__file__).with_name("static")
MESSAGE_LIMIT = 64 * 1024


def create_app(hub: Hub) -> Starlette:
    """The web application for ``hub``."""

    @contextlib.asynccontextmanager
    async def lifespan(_app: Starlette) -> AsyncIterator[None]:
        hub.attach(asyncio.get_running_loop())
        periodic = asyncio.create_task(hub.run_periodic())
        try:
            yield
        finally:
            periodic.cancel()
            with contextlib.suppress(asyncio.CancelledError):
                await periodic

    files = StaticCache(STATIC)

    async def page(request: Request) -> Response:
        return files.respond("index.html", request)

    async def static(request: Request) -> Response:
        return files.respond(request.path_params["path"], request)

    async def robots(_request: Request) -> Response:
        return JSONResponse(hub.robots())

    async def stats(_request: Request) -> Response:
        return JSONResponse({"clients": len(hub.clients), "frames": hub.frames,
                             "trees": sorted(hub.sources),
                             "dropped": sum(client.dropped for client in hub.clients)})

    async def export(request: Request) -> Response:
        try:
            body = await request.json()
            namespace, file_format = body["ns"], body["format"]
            collapsed = [str(uid) for uid in body.get("collapsed", [])]
        except (ValueError, KeyError, TypeError) as exc:
            return JSONResponse({"error": f"export: expected JSON with ns, format and "
                                          f"collapsed ({exc})"}, 400)
        source = hub.sources.get(str(namespace))
        state = source.state if source else None
        if state is None:
            return JSONResponse({"error": f"no tree under {namespace!r}"}, 404)
        text = view_dot(state.structure, statuses=state.statuses_by_id(),
                        active=state.active_ids(), collapsed=collapsed)
        try:
            result = await asyncio.to_thread(render, text, str(file_format),
                                             state.structure.get("title") or "behaviour_tree")
        except ExportError as exc:
            return JSONResponse({"error": str(exc)}, 400)
        return Response(result.content, media_type=result.media_type, headers={
            "Content-Disposition": f'attachment; filename="{result.filename}"'})

    async def websocket(socket: WebSocket) -> None:
        if not _same_origin(socket):
            await socket.close(code=1008, reason="cross-origin connections are refused")
            return
        token = socket.query_params.get("token")
        host = socket.client.host if socket.client else None
        may_control = hub.seat.may_control(host, token)
        await socket.accept()
        client = hub.connect(socket, may_control=may_control)
        writer = asyncio.create_task(_write(hub, client))
        if socket.query_params.get("watch"):  # the page's first connection: no round trip
            await handle(hub, client, {"t": "watch", "ns": hub.default_namespace})
        try:
            while True:
                text = await socket.receive_text()
                if len(text) > MESSAGE_LIMIT:
                    client.send({"t": "error", "message": "message too long"})
                    continue
                try:
                    await handle(hub, client, json.loads(text))
                except (CommandError, ValueError) as exc:
                    client.send({"t": "error", "message": str(exc)})
        except WebSocketDisconnect:
            pass
        finally:
            writer.cancel()
            with contextlib.suppress(asyncio.CancelledError, Exception):
                await writer
            hub.disconnect(client)
            hub.announce_seat()

    routes = [
        Route("/", page),
        Route("/api/robots", robots),
        Route("/api/export", export, methods=["POST"]),
        Route("/stats", stats),
        WebSocketRoute("/ws", websocket),
        Route("/static/{path:path}", static),
    ]
    return Starlette(routes=routes, lifespan=lifespan)


class StaticCache:
    """The page's files, read once and served from memory with an ETag (a reload costs a
    304). The page is small and fixed, so this is quicker than reading files per request."""

    TYPES = {".html": "text/html; charset=utf-8", ".css": "text/css; charset=utf-8",
             ".js": "text/javascript; charset=utf-8", ".mjs": "text/javascript; charset=utf-8",
             ".LICENSE": "text/plain; charset=utf-8"}

    def __init__(self, folder: Path) -> None:
        self.files: dict[str, tuple[bytes, str, str]] = {}
        for path in sorted(folder.rglob("*")):
            if path.is_file() and path.suffix in self.TYPES:
                content = path.read_bytes()
                etag = '"' + hashlib.sha1(content, usedforsecurity=False).hexdigest()[:16] + '"'
                self.files[path.relative_to(folder).as_posix()] = (
                    content, self.TYPES[path.suffix], etag)

    def respond(self, name: str, request: Request) -> Response:
        found = self.files.get(name)
        if found is None:
            return PlainTextResponse(f"no such file: {name}", 404)
        content, media_type, etag = found
        headers = {"ETag": etag, "Cache-Control": "no-cache"}
        if request.headers.get("if-none-match") == etag:
            return Response(status_code=304, headers=headers)
        return Response(content, media_type=media_type, headers=headers)


async def _write(hub: Hub, client: Client) -> None:
    while True:
        text = await client.next_message()
        if text == RESYNC:
            hub.resync(client)
            continue
        try:
            await client.websocket.send_text(text)
        except Exception:
            return
        client.sent += 1


def _same_origin(socket: WebSocket) -> bool:
    """A browser's WebSocket carries its page's Origin; it must be this server's page.
    Clients that send no Origin (scripts, not browsers) are let through."""
    origin = socket.headers.get("origin")
    if not origin:
        return True
    return urlsplit(origin).netloc == socket.headers.get("host", "")
