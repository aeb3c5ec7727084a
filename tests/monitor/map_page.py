"""Helpers for the map panel's browser tests: an ARNL map packed as the monitor's map blob (by
the monitor's own code), synthetic robot messages in the monitor's wire format (docs/monitor.md,
"The map's data path"), and a stand-in monitor that serves the page's own files and lets the
test speak for the monitor on the page's WebSocket. The tests against the real system are
tests/monitor/test_browser_map_live.py.
"""

from __future__ import annotations

import asyncio
import json
import math
import socket
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import uvicorn
from playwright.sync_api import Browser, Page
from starlette.applications import Starlette
from starlette.requests import Request
from starlette.responses import PlainTextResponse, Response
from starlette.routing import Route, WebSocketRoute
from starlette.websockets import WebSocket, WebSocketDisconnect

from cyborg.monitor.map_store import map_blob
from cyborg.monitor.page_files import page_files
from cyborg.nav.arnl_map import ArnlMap
from cyborg.nav.map_message import map_geometry
from tests.monitor.browser import WHOLE_TREE

ROBOT = "/robot1"
START = (-0.5, 0.8, 1.0)
"""Where the robot is first: in columbia's corridor west of its home, heading north-east."""
GOAL_1 = (-3.196, 4.846)
PATH_XY = [-182, 176, -1000, 2000, -2500, 3500, -3196, 4846]
"""Its path in mm, from home to Goal 1."""
BROKEN_KEY = "0123456789abcdef0123456789abcdef"
"""A map key whose blob is not a map."""

def pack_map_blob(arnl_map: ArnlMap) -> bytes:
    """``arnl_map`` as the monitor serves it at ``/api/map/{key}``: the simulator's
    ``map_geometry`` message laid out by the monitor's own :func:`map_blob`, so the stand-in
    cannot drift from the real thing."""
    blob, _header, warnings = map_blob(map_geometry(arnl_map))
    assert warnings == [], warnings
    return blob


def map_ref(ns: str, key: str, arnl_map: ArnlMap) -> dict[str, Any]:
    """The ``map_ref`` message telling the page robot ``ns`` is on map ``key``."""
    return {"t": "map_ref", "ns": ns, "key": key, "url": f"/api/map/{key}",
            "source": Path(arnl_map.source).name,
            "counts": {"points": len(arnl_map.points), "lines": len(arnl_map.lines),
                       "objects": len(arnl_map.objects)}}


def robot_state(ns: str, seq: int, x: float, y: float, theta: float, *,
                beams: int = 541, reach_mm: int = 4000, **extra: Any) -> dict[str, Any]:
    """An ``rs`` message: a pose and a 270° scan whose ranges vary, with a few beams that saw
    nothing (0) or were invalid (-1)."""
    ranges = [0 if i % 97 == 0 else -1 if i % 101 == 0 else
              int(reach_mm * (0.6 + 0.4 * math.sin(i / 23 + seq / 7))) for i in range(beams)]
    scan = {"a0": -3 * math.pi / 4, "da": 3 * math.pi / 2 / (beams - 1), "mx": 30000,
            "r": ranges, "m": [0.267, 0.0, 0.0]}
    return {"t": "rs", "ns": ns, "seq": seq, "p": [round(x, 3), round(y, 3), round(theta, 3)],
            "sc": scan, **extra}


def first_messages(arnl_map: ArnlMap, key: str) -> list[dict[str, Any]]:
    """What a monitor sends a page that opts in: the map, the path, the robot on its way."""
    return [map_ref(ROBOT, key, arnl_map),
            {"t": "path", "ns": ROBOT, "id": 1, "xy": PATH_XY},
            robot_state(ROBOT, 1, *START, st="MOVING_TO_GOAL", pid=1, node="MoveTo Goal 1",
                        goal={"name": "Goal 1", "p": [*GOAL_1, 0.0]})]


class StandInMonitor:
    """The page's files, map blobs and a WebSocket that the test speaks through.

    The page's opt-in ``{"t": "map", "on": true}`` is answered with ``on_map`` (what a monitor
    with maps sends then: map_ref and the robots' state). ``received`` holds what the page
    sent; ``fetches`` counts blob requests.
    """

    def __init__(self, blobs: dict[str, bytes], on_map: list[Any] | None = None) -> None:
        self.blobs = blobs
        self.on_map = on_map or []
        self.received: list[dict[str, Any]] = []
        self.fetches = 0
        self.sockets: set[WebSocket] = set()
        self.loop: asyncio.AbstractEventLoop | None = None
        self.port = 0
        self._server: uvicorn.Server | None = None
        self._thread: threading.Thread | None = None

    @property
    def url(self) -> str:
        return f"http://127.0.0.1:{self.port}/"

    def app(self) -> Starlette:
        files = page_files()

        async def page(request: Request) -> Response:
            return await files.get_response("index.html", request.scope)

        async def static(request: Request) -> Response:
            return await files.get_response(request.path_params["path"], request.scope)

        async def blob(request: Request) -> Response:
            self.fetches += 1
            key = request.path_params["key"]
            if key not in self.blobs:
                return PlainTextResponse("no such map", 404)
            return Response(self.blobs[key], media_type="application/octet-stream", headers={
                "Cache-Control": "public, max-age=31536000, immutable", "ETag": f'"{key}"'})

        async def websocket(ws: WebSocket) -> None:
            await ws.accept()
            self.loop = asyncio.get_running_loop()
            self.sockets.add(ws)
            try:
                while True:
                    message = json.loads(await ws.receive_text())
                    self.received.append(message)
                    if message.get("t") == "hello":
                        await ws.send_text(json.dumps({"t": "seat", "may_control": False,
                                                       "control": False, "holder": None}))
                    if message.get("t") == "map" and message.get("on"):
                        for item in self.on_map:
                            await ws.send_text(item if isinstance(item, str) else
                                               json.dumps(item))
            except WebSocketDisconnect:
                pass
            finally:
                self.sockets.discard(ws)

        return Starlette(routes=[Route("/", page), Route("/static/{path:path}", static),
                                 Route("/api/map/{key}", blob),
                                 WebSocketRoute("/ws", websocket)])

    def __enter__(self) -> StandInMonitor:
        listener = socket.socket()
        listener.bind(("127.0.0.1", 0))
        self.port = listener.getsockname()[1]
        server = self._server = uvicorn.Server(uvicorn.Config(
            self.app(), log_level="warning", lifespan="off", ws_per_message_deflate=False))
        self._thread = threading.Thread(target=server.run, kwargs={"sockets": [listener]},
                                        daemon=True)
        self._thread.start()
        wait_for(lambda: server.started, 10, "the stand-in monitor to start")
        return self

    def __exit__(self, *_exc: object) -> None:
        assert self._server is not None and self._thread is not None
        self._server.should_exit = True
        self._thread.join(10)

    def push(self, *messages: Any) -> None:
        """Send each message (a dict as JSON, a str as it is) to every open page."""
        assert self.loop is not None, "no page connected"
        texts = [item if isinstance(item, str) else json.dumps(item) for item in messages]

        async def send() -> None:
            for ws in list(self.sockets):
                for text in texts:
                    await ws.send_text(text)

        asyncio.run_coroutine_threadsafe(send(), self.loop).result(10)

    def opted_in(self) -> bool | None:
        """The page's latest ``map`` opt-in (None if it sent none)."""
        found = [m.get("on") for m in self.received if m.get("t") == "map"]
        return bool(found[-1]) if found else None


def wait_for(condition: Callable[[], object], timeout: float, what: str) -> None:
    deadline = time.monotonic() + timeout
    while not condition():
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out waiting for {what}")
        time.sleep(0.01)


# ---------------------------------------------------------------------- the page
def open_map_page(browser: Browser, url: str, errors: list[str], width: int = 1000,
                  height: int = 600) -> Page:
    """A fresh page (and browser context) on ``url`` that records console errors into
    ``errors``; waits until the map is drawn. The tree view beside it shows the whole tree
    (browser.py's :data:`WHOLE_TREE`)."""
    page = browser.new_page(viewport={"width": width, "height": height})
    page.add_init_script(WHOLE_TREE)
    page.on("console", lambda message: errors.append(message.text)
            if message.type == "error" else None)
    page.on("pageerror", lambda error: errors.append(str(error)))
    page.goto(url)
    page.wait_for_function("window.__map && window.__map.firstPaint !== null", timeout=20000)
    return page


def on_map(page: Page, expression: str) -> Any:
    """``expression`` evaluated in the page with ``m`` standing for ``window.__map``."""
    return page.evaluate(f"(() => {{ const m = window.__map; return {expression}; }})()")


def pixel(page: Page, sx: float, sy: float) -> list[int]:
    """RGBA of the map's upper canvas at (sx, sy) CSS px."""
    found: list[int] = page.evaluate("""([x, y]) => {
        const canvas = document.getElementById('map-canvas'), dpr = devicePixelRatio;
        return [...canvas.getContext('2d').getImageData(Math.round(x * dpr), Math.round(y * dpr),
                                                        1, 1).data];
    }""", [sx, sy])
    return found


def rgb(colour: str) -> list[int]:
    """``#rrggbb`` as three numbers."""
    return [int(colour[i:i + 2], 16) for i in (1, 3, 5)]


def control_boxes(page: Page) -> dict[str, list[list[float]]]:
    """The map's controls as boxes [x0, y0, x1, y1] in CSS px on its canvas: the toolbar
    (``.map-tools``), each shown control of the actions' bar (``#map-act``) and STOP."""
    found: dict[str, list[list[float]]] = page.evaluate("""() => {
        const origin = document.getElementById('map-canvas').getBoundingClientRect();
        const boxes = (selector) => [...document.querySelectorAll(selector)]
            .map((element) => element.getBoundingClientRect())
            .filter((box) => box.width > 0 && box.height > 0)
            .map((box) => [box.left - origin.left, box.top - origin.top,
                           box.right - origin.left, box.bottom - origin.top]);
        return {toolbar: boxes('#map-view .map-tools'), actions: boxes('#map-act > *'),
                stop: boxes('#map-stop')};
    }""")
    return found


def overlap(a: list[float], b: list[float]) -> bool:
    """Whether boxes ``a`` and ``b`` ([x0, y0, x1, y1]) share any area."""
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]
