"""Helpers for the monitor's protocol tests: a monitor on a running system, reading a page's
WebSocket until a kind of message comes, and giving test connections their own addresses."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from starlette.types import ASGIApp, Receive, Scope, Send

from cyborg.bus import Node
from cyborg.monitor import Monitor
from tests.system import System, running_system

ROOT = Path(__file__).resolve().parents[1]
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


def receive_until(socket: Any, kind: str, limit: int = 400) -> dict[str, Any]:
    """The next message of type ``kind``, skipping others (at most ``limit`` messages)."""
    for _ in range(limit):
        message: dict[str, Any] = socket.receive_json()
        if message["t"] == kind:
            return message
    raise AssertionError(f"no {kind!r} message in {limit} messages")


def watch(socket: Any, namespace: str) -> list[dict[str, Any]]:
    """Watch ``namespace``; returns what the server sent for it, up to its snapshot."""
    socket.send_json({"t": "watch", "ns": namespace})
    receive_until(socket, "watching")
    sent: list[dict[str, Any]] = []
    while not sent or sent[-1]["t"] != "snapshot":
        sent.append(socket.receive_json())
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
