"""Helpers for the monitor's protocol tests: a monitor on a running system or on an empty bus, a
hub over fake trees (no bus at all), reading a page's WebSocket until a kind of message comes,
and giving test connections their own addresses."""

from __future__ import annotations

import json
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any, ClassVar, cast

import anyio
from starlette.testclient import TestClient
from starlette.types import ASGIApp, Receive, Scope, Send
from starlette.websockets import WebSocketDisconnect

from cyborg.bus import BusConfig, Context, Node
from cyborg.monitor import Monitor
from cyborg.monitor.hub import Hub
from cyborg.monitor.limits import Limits
from cyborg.monitor.seat import ControlSeat
from cyborg.monitor.source import CONTROL_ACTIONS, STATUSES, ControlError, TreeSource
from cyborg.monitor.tree_state import TreeState
from tests.running_system import System, running_system

ROOT = Path(__file__).resolve().parents[2]
CAMPUS_MAP = ROOT / "src/cyborg/app/data/campus.map"
CAMPUS_TREE = ROOT / "src/cyborg/app/data/campus_patrol.b3.json"


@contextmanager
def campus_system() -> Iterator[System]:
    """The campus robot, simulated at ten times real time."""
    with running_system(CAMPUS_MAP, CAMPUS_TREE, speed=10.0) as running:
        yield running


def monitor_for(system: System, token: str | None = None,
                namespaces: list[str] | None = None) -> Monitor:
    """A monitor following ``namespaces`` (default ``/cyborg/bt``), not serving: drive its
    ``app`` with Starlette's test client."""
    return Monitor(Node("monitor", "/cyborg", context=system.context),
                   namespaces=namespaces or ["/cyborg/bt"], token=token)


RECEIVE_TIMEOUT = 15.0
"""Seconds a test waits for the server's next message (the test client itself waits forever)."""


def next_json(socket: Any, timeout: float = RECEIVE_TIMEOUT) -> dict[str, Any]:
    """The server's next message on a test client's WebSocket, waiting at most ``timeout``."""
    async def receive() -> Any:
        with anyio.fail_after(timeout):
            return await socket._send_rx.receive()

    try:
        message = socket.portal.call(receive)
    except TimeoutError:
        raise AssertionError(f"no message from the monitor within {timeout:g} s") from None
    if message["type"] == "websocket.close":
        raise WebSocketDisconnect(message.get("code", 1000), message.get("reason", ""))
    decoded: dict[str, Any] = json.loads(message["text"])
    return decoded


def receive_until(socket: Any, kind: str, limit: int = 400) -> dict[str, Any]:
    """The next message of type ``kind``, skipping others (at most ``limit`` messages, each
    within :data:`RECEIVE_TIMEOUT`)."""
    for _ in range(limit):
        message = next_json(socket)
        if message["t"] == kind:
            return message
    raise AssertionError(f"no {kind!r} message in {limit} messages")


def watch(socket: Any, namespace: str) -> list[dict[str, Any]]:
    """Watch ``namespace``; returns what the server sent for it, up to its snapshot."""
    socket.send_json({"t": "watch", "ns": namespace})
    receive_until(socket, "watching")
    sent: list[dict[str, Any]] = []
    while not sent or sent[-1]["t"] != "snapshot":
        sent.append(next_json(socket))
        assert len(sent) < 50, f"no snapshot for {namespace}"
    return sent


def peer_from_header(app: ASGIApp) -> ASGIApp:
    """``app`` seeing each connection come from the address in its ``x-peer`` header (a
    test client gives all its connections one address)."""
    async def from_header(scope: Scope, receive: Receive, send: Send) -> None:
        peer = dict(scope.get("headers") or []).get(b"x-peer")
        if peer is not None:
            scope = {**scope, "client": (peer.decode(), 50001)}
        await app(scope, receive, send)
    return from_header


def _node(uid: str, name: str, category: str, *children: dict[str, Any]) -> dict[str, Any]:
    return {"id": uid, "label": uid, "name": name, "category": category,
            "children": list(children)}


SMALL_TREE = json.dumps({"title": "small", "root": _node(
    "root", "Priority", "composite", _node("seq", "Sequence", "composite",
                                           _node("leaf0", "Succeeder", "action"),
                                           _node("leaf1", "Failer", "action")))})


class FakeSource:
    """A tree runner without a bus: what a :class:`Hub` asks of a source, answered at once.
    ``created`` and ``destroyed`` count, over all fakes, which namespaces were followed."""

    created: ClassVar[list[str]] = []
    destroyed: ClassVar[list[str]] = []
    running: ClassVar[set[str]] = set()
    """Namespaces a (pretend) tree runner is in."""

    def __init__(self, namespace: str) -> None:
        self.namespace = namespace
        self.state: TreeState | None = TreeState(SMALL_TREE)
        self.generation, self.enabled = 1, True
        self.stopped: bool | None = False
        self.hooks: list[dict[str, Any]] = []
        self.paused_at = self.problem = ""
        FakeSource.created.append(namespace)

    @property
    def alive(self) -> bool:
        return self.namespace in FakeSource.running

    def describe(self) -> dict[str, Any]:
        return {"ns": self.namespace, "alive": self.alive, "enabled": self.enabled,
                "stopped": self.stopped, "title": "small", "nodes": 3, "tick": 0, "problem": ""}

    def set_enabled(self, on: bool) -> str:
        self.enabled = on
        self.stopped = self.stopped and not on
        return "ok"

    def stop(self) -> str:
        self.enabled, self.stopped = False, True
        return "stopped"

    def control(self, node_id: str, action: str, status: str = "failure", *,
                once: bool = False, keep: bool = False) -> str:
        if action not in CONTROL_ACTIONS or status not in STATUSES:
            raise ControlError(f"unknown action {action!r} or status {status!r}")
        return "ok"

    def trigger(self, service: str) -> str:
        raise ControlError(f"{service}: not at a breakpoint")

    def blackboard(self) -> dict[str, Any]:
        return {"global": {}, "tree": {}, "node": {}}

    def services_message(self) -> dict[str, Any] | None:
        return None  # a tree without services

    def destroy(self) -> None:
        FakeSource.destroyed.append(self.namespace)


def bare_hub(token: str | None = None, namespaces: tuple[str, ...] = ("/cyborg/bt",),
             limits: Limits | None = None, runners: tuple[str, ...] = ("/cyborg/bt",)) -> Hub:
    """A hub over :class:`FakeSource` trees (no bus), started with ``namespaces``, with tree
    runners in ``runners`` (``FakeSource.running``: change it to start or stop one)."""
    FakeSource.created.clear()
    FakeSource.destroyed.clear()
    FakeSource.running = set(runners)
    hub = Hub(cast(Callable[[str], TreeSource], FakeSource),
              lambda: sorted(FakeSource.running), default_namespace=namespaces[0],
              seat=ControlSeat(token), limits=limits or Limits())
    for namespace in namespaces:
        hub.follow(namespace, pinned=True)
    return hub


class PageClient(TestClient):
    """Starlette's test client with its WebSockets sent to ``base_url``'s host too (the
    plain test client names ``testserver`` in a WebSocket's Host header)."""

    def websocket_connect(self, url: str, *args: Any, **kwargs: Any) -> Any:
        if url.startswith("/"):
            scheme = "wss" if self.base_url.scheme == "https" else "ws"
            url = f"{scheme}://{self.base_url.netloc.decode()}{url}"
        return super().websocket_connect(url, *args, **kwargs)


def local_client(app: ASGIApp, peer: str = "127.0.0.1",
                 base_url: str = "http://127.0.0.1:8080") -> TestClient:
    """Starlette's test client as a browser on ``peer`` that opened ``base_url``."""
    return PageClient(app, base_url=base_url, client=(peer, 50000))


@contextmanager
def bus_monitor(token: str | None = None) -> Iterator[Monitor]:
    """A monitor on an isolated bus with no tree runner (not serving)."""
    with Context(BusConfig.isolated()) as context:
        monitor = Monitor(Node("monitor", "/cyborg", context=context),
                          namespaces=["/cyborg/bt"], token=token)
        try:
            yield monitor
        finally:
            monitor.stop()
