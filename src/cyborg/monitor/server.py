"""The monitor's web application (Starlette): the page, its WebSocket, exports, health.

==============================  ===============================================================
route                           what
==============================  ===============================================================
``GET /``                       the page (plain ES modules from ``/static``, no build step)
``GET /static/...``             its scripts, styles and the vendored d3-hierarchy
``WS /ws``                      live updates and commands (:mod:`cyborg.monitor.commands`)
``GET /api/robots``             the trees the monitor follows, as JSON
``GET /api/map/{key}``          a robot's map as a binary blob (:mod:`cyborg.monitor.map_route`)
``POST /api/export``            ``{"ns", "format": dot|svg|png, "collapsed": [ids]}`` → file
``GET /stats``                  counters, for health checks and benchmarks
==============================  ===============================================================

Every request must name this monitor in its ``Host`` header (:class:`HostGuard`; DNS
rebinding), or it gets ``403``. A browser's WebSocket must come from the monitor's own page (its
``Origin`` has the scheme, host and port of the request), or present the token; so no other web
page can drive the robot through a user's browser, even one on this machine. Requests are
bounded (:mod:`cyborg.monitor.limits`) and answered, never with a traceback. See
docs/security.md.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import logging
from collections.abc import AsyncIterator, Awaitable, Callable

from starlette.applications import Starlette
from starlette.requests import ClientDisconnect, Request
from starlette.responses import JSONResponse, PlainTextResponse, Response
from starlette.routing import Route, WebSocketRoute
from starlette.types import ASGIApp, Receive, Scope, Send
from starlette.websockets import WebSocket, WebSocketDisconnect

from cyborg.monitor.access import HostPolicy, own_origin
from cyborg.monitor.client import RESYNC, Client
from cyborg.monitor.commands import located_error, receive
from cyborg.monitor.export import ExportError, render, view_dot
from cyborg.monitor.hub import Hub
from cyborg.monitor.limits import BODY_LIMIT, check_namespace, decode
from cyborg.monitor.map_route import map_endpoint
from cyborg.monitor.off_loop import in_thread
from cyborg.monitor.page_files import PageSource, page_files
from cyborg.monitor.refusal import RefusalError
from cyborg.monitor.seat import is_loopback

log = logging.getLogger("cyborg.monitor")

EXPORTS_AT_ONCE = 2
"""Graphviz runs at a time; more export requests are told to try again (503)."""


def create_app(hub: Hub, *, hosts: HostPolicy | None = None,
               files: PageSource | None = None) -> ASGIApp:
    """The web application for ``hub``: the page, its WebSocket and its HTTP API.

    It answers only the names ``hosts`` allows (default: this machine's names and addresses),
    and serves the page's ``files`` (default: from memory,
    :func:`~cyborg.monitor.page_files.page_files`).
    """

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
            await hub.robot_hub.detach()
            hub.player.detach()
            hub.modes.detach()

    files = files or page_files()

    async def page(request: Request) -> Response:
        return await files.get_response("index.html", request.scope)

    async def static(request: Request) -> Response:
        return await files.get_response(request.path_params["path"], request.scope)

    async def robots(_request: Request) -> Response:
        return JSONResponse(hub.robots())

    async def stats(_request: Request) -> Response:
        return JSONResponse({"clients": len(hub.clients), "frames": hub.frames,
                             "trees": sorted(hub.sources),
                             "dropped": sum(client.dropped for client in hub.clients),
                             "map_fetches": hub.robot_hub.store.fetches})

    routes = [
        Route("/", page),
        Route("/api/robots", robots),
        Route("/api/map/{key}", map_endpoint(hub.robot_hub.store)),
        Route("/api/export", export_endpoint(hub), methods=["POST"]),
        Route("/stats", stats),
        WebSocketRoute("/ws", websocket_endpoint(hub)),
        Route("/static/{path:path}", static),
    ]
    return HostGuard(Starlette(routes=routes, lifespan=lifespan), hosts or HostPolicy())


def export_endpoint(hub: Hub) -> Callable[[Request], Awaitable[Response]]:
    """``POST /api/export``: a watched tree drawn by Graphviz (SVG, PNG, PDF, DOT), two at a time.

    Refused to a page of another origin (403), past :data:`BODY_LIMIT` (413), for a body that
    is not the expected JSON (400), an unknown tree (404) or while Graphviz is busy (503).
    """
    exports = asyncio.Semaphore(EXPORTS_AT_ONCE)

    async def export(request: Request) -> Response:
        origin = request.headers.get("origin")
        if origin is not None and not own_origin(origin, request.url.scheme,
                                                 request.headers.get("host")):
            return JSONResponse({"error": "export: refused to a page of another origin"}, 403)
        try:
            body = decode((await _read_body(request)).decode("utf-8"))
            namespace = check_namespace(body["ns"])
            file_format = str(body["format"])
            collapsed = [str(uid) for uid in body.get("collapsed", [])]
        except _TooLargeError:
            return JSONResponse({"error": f"export: a request has at most {BODY_LIMIT} "
                                          "bytes"}, 413)
        except (RefusalError, ValueError, KeyError, TypeError, AttributeError) as exc:
            return JSONResponse({"error": f"export: expected JSON with ns, format and "
                                          f"collapsed ({_reason(exc)})"}, 400)
        source = hub.sources.get(namespace)
        state = source.state if source else None
        if state is None:
            return JSONResponse({"error": f"no tree under {namespace!r}"}, 404)
        if exports.locked():
            return JSONResponse({"error": "export: Graphviz is busy; try again"}, 503)
        text = view_dot(state.structure, statuses=state.statuses_by_id(),
                        active=state.active_ids(), collapsed=collapsed)
        async with exports:
            try:
                result = await in_thread(render, text, file_format,
                                                 state.structure.get("title") or "behaviour_tree")
            except (ExportError, ValueError) as exc:
                return JSONResponse({"error": str(exc)}, 400)
        return Response(result.content, media_type=result.media_type, headers={
            "Content-Disposition": f'attachment; filename="{result.filename}"'})

    return export


def websocket_endpoint(hub: Hub) -> Callable[[WebSocket], Awaitable[None]]:
    """``/ws``: one page's connection to ``hub``, from the origin and seat checks to its end.

    A page of another origin needs the token; past the connection limits the page is told why
    and closed (1008). Each message is carried out by :func:`~cyborg.monitor.commands.receive`,
    and what the hub sends goes out through a writer task of the connection's own.
    """

    async def websocket(socket: WebSocket) -> None:
        origin = socket.headers.get("origin")
        own = origin is None or own_origin(origin, socket.url.scheme,
                                           socket.headers.get("host"))
        token_ok = hub.seat.token_matches(socket.query_params.get("token"))
        if not own and not token_ok:
            await socket.close(code=1008, reason="cross-origin connections are refused")
            return
        host = socket.client.host if socket.client else None
        await socket.accept()
        refusal = hub.refusal(host)  # counted and connected with no await between
        if refusal is not None:
            await socket.send_text(json.dumps({"t": "error", "n": 0, "req": None,
                                               "command": None, "field": None, "pos": None,
                                               "message": refusal}))
            await socket.close(code=1008, reason="too many connections")
            return
        client = hub.connect(socket, may_control=token_ok or (own and is_loopback(host)))
        writer = asyncio.create_task(_write(hub, client))
        if socket.query_params.get("watch"):  # the page's first connection: no round trip
            try:
                hub.watch(client, hub.default_namespace)
            except (ValueError, RefusalError) as exc:
                client.send(located_error(client, None, exc))
        try:
            while True:
                message = await socket.receive()
                if message["type"] == "websocket.disconnect":
                    break
                await receive(hub, client, message.get("text"))
        except WebSocketDisconnect:
            pass
        finally:
            writer.cancel()
            with contextlib.suppress(asyncio.CancelledError, Exception):
                await writer
            hub.disconnect(client)

    return websocket


class HostGuard:
    """ASGI middleware: ``403`` to every request whose ``Host`` header ``hosts`` does not allow.

    HTTP requests and WebSockets alike: a WebSocket gets a denial response where the server
    supports it, else a close before the handshake, which servers answer with 403.
    """

    def __init__(self, app: ASGIApp, hosts: HostPolicy) -> None:
        self.app, self.hosts = app, hosts

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        """Passes an allowed request (and lifespan events) on to the app; refuses the rest."""
        if scope["type"] not in ("http", "websocket"):
            await self.app(scope, receive, send)
            return
        host = _header(scope, b"host")
        if self.hosts.allows(host):
            await self.app(scope, receive, send)
            return
        log.info("refused a request for host %r (not an allowed name)", host)
        refusal = PlainTextResponse(self.hosts.refusal(host), 403)
        if scope["type"] == "http" or "websocket.http.response" in scope.get("extensions", {}):
            await refusal(scope, receive, send)
        else:
            await send({"type": "websocket.close", "code": 1008})


def _header(scope: Scope, name: bytes) -> str | None:
    for key, value in scope.get("headers") or ():
        if key == name:
            return bytes(value).decode("latin-1")
    return None


class _TooLargeError(Exception):
    pass


async def _read_body(request: Request) -> bytes:
    """The request's body, up to :data:`BODY_LIMIT` bytes (:class:`_TooLargeError` beyond)."""
    length = request.headers.get("content-length", "")
    if length.isdigit() and int(length) > BODY_LIMIT:
        raise _TooLargeError
    chunks, size = [], 0
    try:
        async for chunk in request.stream():
            size += len(chunk)
            if size > BODY_LIMIT:
                raise _TooLargeError
            chunks.append(chunk)
    except ClientDisconnect:
        raise ValueError("the client went away") from None
    return b"".join(chunks)


def _reason(exc: Exception) -> str:
    if isinstance(exc, KeyError):
        return f"missing {exc}"
    return str(exc) if isinstance(exc, RefusalError | ValueError) else type(exc).__name__


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
