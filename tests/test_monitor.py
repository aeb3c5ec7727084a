"""The web monitor without a browser: tree state and deltas, the control seat, exports, and the
WebSocket protocol against a running system (Starlette's test client)."""

from __future__ import annotations

import json
import math
import struct
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from starlette.testclient import TestClient
from starlette.websockets import WebSocketDisconnect

from cyborg.bt import load_tree
from cyborg.bt.clock import ManualClock
from cyborg.bus import Node
from cyborg.monitor import Monitor
from cyborg.monitor.export import (
    MAX_PNG_PIXELS,
    MIN_PX_PER_LEAF,
    ExportError,
    render,
    view_dot,
)
from cyborg.monitor.seat import ControlSeat, is_loopback
from cyborg.monitor.tree_state import FRESH, StructureError, TreeState
from cyborg.nodes.tree_runner import TreeRunnerNode
from tests.builders import N, tree_from
from tests.system import System, running_system, wait_until

CAMPUS_MAP = Path(__file__).resolve().parents[1] / "src/cyborg/app/data/campus.map"
CAMPUS_TREE = Path(__file__).resolve().parents[1] / "src/cyborg/app/data/campus_patrol.b3.json"


def _structure(children: int = 2) -> str:
    leaves = [{"id": f"leaf{i}", "children": []} for i in range(children)]
    return json.dumps({"title": "t", "root": {"id": "root", "children": [
        {"id": "seq", "children": leaves}]}})


def _tick(state: TreeState, tick: int, visits: dict[str, int], active: list[str],
          durations: list[float] | None = None) -> None:
    state.apply_tick(tick, tick * 0.1, 0.001, 3, list(visits),
                     np.array(list(visits.values()), np.uint8),
                     np.array(durations if durations is not None else [], np.float32), active)


# ---------------------------------------------------------------------------------- tree state
def test_frames_carry_only_what_changed_and_mark_what_ran_this_tick() -> None:
    state = TreeState(_structure())
    assert state.ids == ["root", "seq", "leaf0", "leaf1"], "pre-order indices"
    _tick(state, 1, {"leaf0": 3, "seq": 3, "root": 3}, ["root", "seq", "leaf0"])
    first = state.frame()
    assert first is not None and first["seq"] == 1 and first["act"] == [0, 1, 2]
    assert dict(zip(first["ch"][0::2], first["ch"][1::2], strict=True)) == {
        0: 3 + FRESH, 1: 3 + FRESH, 2: 3 + FRESH}
    assert state.frame() is None, "nothing new, nothing sent"
    _tick(state, 2, {"leaf0": 1, "leaf1": 3, "seq": 3, "root": 3}, ["root", "seq", "leaf1"])
    second = state.frame()
    assert second is not None
    assert dict(zip(second["ch"][0::2], second["ch"][1::2], strict=True)) == {
        2: 1 + FRESH, 3: 3 + FRESH}, "root and seq look the same: not sent"
    assert second["act"] == [0, 1, 3] and second["tick"] == 2
    _tick(state, 3, {"leaf1": 3, "seq": 3, "root": 3}, ["root", "seq", "leaf1"])
    third = state.frame()
    assert third is not None and "act" not in third, "the active path is sent when it changes"
    assert dict(zip(third["ch"][0::2], third["ch"][1::2], strict=True)) == {2: 1}, \
        "leaf0 keeps its last status but did not run this tick"
    snapshot = state.snapshot()
    assert snapshot["codes"] == [3 + FRESH, 3 + FRESH, 1, 3 + FRESH]
    assert snapshot["seq"] == third["seq"]


def test_timings_history_and_unknown_ids() -> None:
    state = TreeState(_structure(), history=3)
    for tick in range(1, 6):
        _tick(state, tick, {"leaf0": 1, "ghost": 2, "root": 1}, [],
              durations=[0.002 * tick, 0.5, 0.003 * tick])
    rows = {row[0]: row for row in state.timings()}
    assert set(rows) == {0, 2}, "the unknown id is ignored"
    _index, calls, last, mean, low, high, changes, _since = rows[2]
    assert (calls, changes) == (5, 1)
    assert math.isclose(last, 10.0) and math.isclose(mean, 6.0)
    assert (math.isclose(low, 2.0), math.isclose(high, 10.0)) == (True, True)
    assert state.timings() == [], "only what changed since the last call"
    _tick(state, 6, {"leaf0": 1}, [], durations=[0.001])
    assert len(state.timings(all_nodes=True)) == 2, "a new page gets every timed node"
    assert [row[0] for row in state.timings()] == [2], "and the others still get the change"
    history = state.history_json()
    assert [entry[0] for entry in history] == [4, 5, 6], "a bounded ring of recent ticks"
    assert history[-2][4] == [2, 0] and history[-2][5] == [1, 1]


def test_a_structure_that_is_not_one_is_refused() -> None:
    with pytest.raises(StructureError, match="not a tree structure"):
        TreeState("{not json")
    with pytest.raises(StructureError):
        TreeState(json.dumps({"root": {"children": []}}))


# ---------------------------------------------------------------------------------- seat
@pytest.mark.parametrize(("host", "local"), [
    ("127.0.0.1", True), ("127.8.0.2", True), ("::1", True), ("::ffff:127.0.0.1", True),
    ("192.0.2.2", False), ("10.0.0.7", False), ("testclient", False), (None, False),
    ("::ffff:192.0.2.9", False)])
def test_loopback_detection(host: str | None, local: bool) -> None:
    assert is_loopback(host) is local


def test_one_controlling_client_a_token_for_others_and_a_grace_period() -> None:
    seat = ControlSeat(token="s3cret", grace=10.0)
    assert seat.may_control("127.0.0.1", None)
    assert not seat.may_control("192.0.2.9", None)
    assert not seat.may_control("192.0.2.9", "wrong")
    assert seat.may_control("192.0.2.9", "s3cret")
    assert not ControlSeat().may_control("192.0.2.9", ""), "no token configured: view only"
    assert seat.claim("a") == (True, None)
    assert seat.claim("b") == (False, None), "one controlling client at a time"
    seat.note_hook("/cyborg/bt", "n1", set_=True)
    assert seat.claim("b", force=True) == (True, "a")
    assert seat.holds("b") and not seat.holds("a")
    seat.disconnected("b", now=100.0)
    assert seat.expired(now=105.0) is None, "a reloading page keeps the seat"
    assert seat.claim("b") == (True, None) and seat.holds("b")
    seat.disconnected("b", now=200.0)
    assert seat.expired(now=211.0) == {("/cyborg/bt", "n1")}, "its hooks are released"
    assert seat.holder is None
    assert seat.claim("c") == (True, None)


# ---------------------------------------------------------------------------------- export
def test_export_draws_what_is_shown() -> None:
    tree = load_tree(CAMPUS_TREE, clock=ManualClock())
    snapshot = tree.tick()
    structure = tree.structure.to_json()
    patrol_node = next(node for node in tree if node.label == "Patrol")
    patrol = patrol_node.uid
    hidden = sum(1 for _ in patrol_node.walk()) - 1
    statuses = {uid: status.label for uid, status in snapshot.visited}
    text = view_dot(structure, statuses=statuses, active=snapshot.active, collapsed=[patrol])
    assert f"(+{hidden})" in text, "a folded node says how many it hides"
    below = [node for node in tree if node.label.startswith("MoveTo Library")]
    assert below and all(node.uid not in text for node in below)
    running = tree_from(N("Sequence", N("Sequence", N("Scripted", script="R", id="leaf"),
                                        id="inner"), N("Succeeder", id="other"), id="top"))
    tick = running.tick()
    drawn = view_dot(running.structure.to_json(), statuses={}, active=tick.active,
                     collapsed=[])
    assert '"top" -> "inner" [color="#d93025", style=dashed' in drawn, \
        "the active path, as rqt_bt drew it"
    assert '"top" -> "other";' in drawn
    svg = render(text, "svg", "Campus mission")
    assert svg.filename == "Campus_mission.svg" and b"<svg" in svg.content
    png = render(text, "png", "Campus mission")
    assert png.content[:8] == b"\x89PNG\r\n\x1a\n"
    with pytest.raises(ExportError, match="unknown format 'gif'"):
        render(text, "gif", "x")


def _wide(count: int) -> dict[str, Any]:
    nodes = [{"id": f"n{i}", "label": f"Action number {i}", "name": "Wait", "category": "action",
              "children": []} for i in range(count)]
    groups = [{"id": f"g{i}", "label": f"Sequence {i}", "name": "Sequence",
               "category": "composite", "children": nodes[i::20]} for i in range(20)]
    return {"title": "wide", "root": {"id": "root", "label": "root", "name": "Priority",
                                      "category": "composite", "children": groups}}


def test_a_large_tree_still_gives_a_usable_png() -> None:
    structure = _wide(1000)
    text = view_dot(structure, statuses={}, active=[], collapsed=[])
    assert "rankdir=LR" in text, "wide trees are laid out left to right"
    png = render(text, "png", "wide").content
    width, height = struct.unpack(">II", png[16:24])
    assert max(width, height) <= MAX_PNG_PIXELS + 1, "below cairo's limit: nothing shrunk"
    assert height / 1000 >= MIN_PX_PER_LEAF, f"{width}x{height} px: rows too thin to read"


# ---------------------------------------------------------------------------------- protocol
@pytest.fixture
def system() -> Iterator[System]:
    with running_system(CAMPUS_MAP, CAMPUS_TREE, speed=10.0) as running:
        yield running


def _monitor(system: System, token: str | None = None) -> Monitor:
    return Monitor(Node("monitor", "/cyborg", context=system.context),
                   namespaces=["/cyborg/bt"], token=token)


def _receive_until(socket: Any, kind: str, limit: int = 400) -> dict[str, Any]:
    for _ in range(limit):
        message: dict[str, Any] = socket.receive_json()
        if message["t"] == kind:
            return message
    raise AssertionError(f"no {kind!r} message in {limit} messages")


def test_the_page_gets_structure_snapshot_and_deltas_and_controls_from_loopback(
        system: System) -> None:
    monitor = _monitor(system)
    try:
        wait_until(lambda: monitor.hub.sources["/cyborg/bt"].state is not None, 10,
                   "the structure")
        with TestClient(monitor.app, client=("127.0.0.1", 50000)) as client, \
                client.websocket_connect("/ws") as socket:
            socket.send_json({"t": "hello", "key": "page-1"})
            seat = _receive_until(socket, "seat")
            assert seat["may_control"] and seat["holder"] is None
            socket.send_json({"t": "watch", "ns": "/cyborg/bt"})
            structure = _receive_until(socket, "structure")
            assert structure["tree"]["title"] == "Campus mission"
            snapshot = _receive_until(socket, "snapshot")
            assert len(snapshot["codes"]) == structure["tree"]["node_count"] == 22
            ticks = [_receive_until(socket, "tick") for _ in range(5)]
            assert [frame["seq"] for frame in ticks] == sorted({f["seq"] for f in ticks})
            assert all(frame["v"] == structure["v"] for frame in ticks)
            socket.send_json({"t": "enable", "on": False, "req": 7})
            refused = _receive_until(socket, "result")
            assert (refused["req"], refused["ok"]) == (7, False)
            assert "take control first" in refused["message"]
            socket.send_json({"t": "claim", "req": 8})
            assert _receive_until(socket, "result")["ok"] is True
            socket.send_json({"t": "enable", "on": False, "req": 9})
            assert _receive_until(socket, "result")["ok"] is True
            wait_until(lambda: not system.runner.enabled, 5, "the tree paused")
            socket.send_json({"t": "control", "id": "nope", "action": "disable", "req": 10})
            assert "no node 'nope'" in _receive_until(socket, "result")["message"]
            socket.send_json({"t": "history", "req": 11})
            history = _receive_until(socket, "history")
            assert len(history["ticks"]) > 3
            socket.send_json({"t": "frobnicate"})
            assert "unknown command" in _receive_until(socket, "error")["message"]
            socket.send_json({"t": "enable", "on": True, "req": 12})
            assert _receive_until(socket, "result")["ok"] is True
            wait_until(lambda: system.runner.enabled, 5, "the tree running again")
            response = client.post("/api/export", json={"ns": "/cyborg/bt", "format": "dot",
                                                        "collapsed": []})
            assert response.status_code == 200 and response.text.startswith("digraph")
            bad = client.post("/api/export", content=b"nope")
            assert bad.status_code == 400 and "expected JSON" in bad.json()["error"]
            missing = client.post("/api/export", json={"ns": "/elsewhere", "format": "svg"})
            assert missing.status_code == 404
    finally:
        monitor.stop()


def test_other_machines_watch_but_do_not_control_without_the_token(system: System) -> None:
    monitor = _monitor(system, token="s3cret")
    try:
        with TestClient(monitor.app, client=("192.0.2.9", 50000)) as client:
            with client.websocket_connect("/ws") as socket:
                socket.send_json({"t": "hello", "key": "far"})
                assert _receive_until(socket, "seat")["may_control"] is False
                socket.send_json({"t": "watch", "ns": "/cyborg/bt"})
                _receive_until(socket, "tick")
                socket.send_json({"t": "enable", "on": False, "req": 1})
                assert "view only" in _receive_until(socket, "result")["message"]
                socket.send_json({"t": "claim", "req": 2})
                assert "view only" in _receive_until(socket, "error")["message"]
            assert system.runner.enabled
            with client.websocket_connect("/ws?token=s3cret") as socket:
                socket.send_json({"t": "hello", "key": "far-with-token"})
                assert _receive_until(socket, "seat")["may_control"] is True
            with pytest.raises(WebSocketDisconnect) as refused, client.websocket_connect(
                    "/ws", headers={"origin": "http://evil.example"}) as socket:
                socket.receive_json()
            assert refused.value.code == 1008, "another site's page may not connect"
    finally:
        monitor.stop()


def _watch(socket: Any, namespace: str) -> list[dict[str, Any]]:
    """Watch ``namespace``; returns what the server sent for it, up to its snapshot."""
    socket.send_json({"t": "watch", "ns": namespace})
    _receive_until(socket, "watching")
    sent: list[dict[str, Any]] = []
    while not sent or sent[-1]["t"] != "snapshot":
        sent.append(socket.receive_json())
        assert len(sent) < 50, f"no snapshot for {namespace}"
    return sent


def test_a_page_that_returns_to_a_robot_gets_its_tree_again(system: System,
                                                            shared: Path) -> None:
    other = TreeRunnerNode(Node("tree_runner", "/other/bt", context=system.context),
                           shared / "trees" / "stock_nodes.tree.json")
    other.start()
    monitor = Monitor(Node("monitor", "/cyborg", context=system.context),
                      namespaces=["/cyborg/bt", "/other/bt"])
    try:
        wait_until(lambda: all(source.state is not None
                               for source in monitor.hub.sources.values()), 10, "both trees")
        with TestClient(monitor.app, client=("127.0.0.1", 50000)) as client, \
                client.websocket_connect("/ws") as socket:
            for namespace in ("/cyborg/bt", "/other/bt", "/cyborg/bt", "/other/bt"):
                sent = _watch(socket, namespace)
                version = monitor.hub.sources[namespace].state.version  # type: ignore[union-attr]
                structures = [message for message in sent if message["t"] == "structure"]
                assert [(message["ns"], message["v"]) for message in structures] == [
                    (namespace, version)], f"the page shows another tree: {namespace} again"
                assert sent[-1]["v"] == version
                tick = _receive_until(socket, "tick")
                assert (tick["ns"], tick["v"]) == (namespace, version)
            socket.send_json({"t": "refresh"})
            again = _receive_until(socket, "structure")
            assert again["ns"] == "/other/bt", "Refresh sends the structure again"
            socket.send_json({"t": "watch", "ns": "/other/bt"})
            _receive_until(socket, "watching")
            assert all(message["t"] != "structure"
                       for message in [socket.receive_json() for _ in range(3)]), \
                "watching the tree the page shows again needs no structure"
    finally:
        monitor.stop()
        other.destroy()
