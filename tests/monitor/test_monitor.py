"""The web monitor without a browser: tree state and deltas, exports, and the WebSocket protocol
against a running system (Starlette's test client). The control seat: test_monitor_seat.py."""

from __future__ import annotations

import json
import math
import struct
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from cyborg.bt import load_tree
from cyborg.bt.clock import ManualClock
from cyborg.bt.outline import StructureError
from cyborg.bus import Node
from cyborg.monitor.client import QUEUE_LIMIT
from cyborg.monitor.export import (
    MAX_PNG_PIXELS,
    MIN_PX_PER_LEAF,
    ExportError,
    render,
    view_dot,
)
from cyborg.monitor.tree_state import FRESH, TreeState
from cyborg.runner.tree_runner import TreeRunnerNode
from tests.builders import N, tree_from
from tests.monitor.monitor_protocol import (
    CAMPUS_TREE,
    campus_system,
    local_client,
    monitor_for,
    next_json,
    receive_until,
    watch,
)
from tests.running_system import System, wait_until


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
    with campus_system() as running:
        yield running


def test_the_page_gets_structure_snapshot_and_deltas_and_controls_from_loopback(
        system: System) -> None:
    monitor = monitor_for(system)
    try:
        wait_until(lambda: monitor.hub.sources["/cyborg/bt"].state is not None, 10,
                   "the structure")
        with local_client(monitor.app) as client, \
                client.websocket_connect("/ws") as socket:
            socket.send_json({"t": "hello", "key": "page-1"})
            seat = receive_until(socket, "seat")
            assert seat["may_control"] and seat["holder"] is None
            socket.send_json({"t": "watch", "ns": "/cyborg/bt"})
            structure = receive_until(socket, "structure")
            assert structure["tree"]["title"] == "Campus mission"
            snapshot = receive_until(socket, "snapshot")
            assert len(snapshot["codes"]) == structure["tree"]["node_count"] == 22
            ticks = [receive_until(socket, "tick") for _ in range(5)]
            assert [frame["seq"] for frame in ticks] == sorted({f["seq"] for f in ticks})
            assert all(frame["v"] == structure["v"] for frame in ticks)
            socket.send_json({"t": "enable", "on": False, "req": 7})
            refused = receive_until(socket, "result")
            assert (refused["req"], refused["ok"]) == (7, False)
            assert "take control first" in refused["message"]
            socket.send_json({"t": "claim", "req": 8})
            assert receive_until(socket, "result")["ok"] is True
            socket.send_json({"t": "enable", "on": False, "req": 9})
            assert receive_until(socket, "result")["ok"] is True
            wait_until(lambda: not system.runner.enabled, 5, "the tree paused")
            socket.send_json({"t": "control", "id": "nope", "action": "disable", "req": 10})
            assert "no node 'nope'" in receive_until(socket, "result")["message"]
            socket.send_json({"t": "history", "req": 11})
            history = receive_until(socket, "history")
            assert len(history["ticks"]) > 3
            socket.send_json({"t": "frobnicate"})
            assert "unknown command" in receive_until(socket, "error")["message"]
            socket.send_json({"t": "enable", "on": True, "req": 12})
            assert receive_until(socket, "result")["ok"] is True
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


def test_a_page_that_returns_to_a_robot_gets_its_tree_again(system: System,
                                                            shared: Path) -> None:
    other = TreeRunnerNode(Node("tree_runner", "/other/bt", context=system.context),
                           shared / "trees" / "stock_nodes.tree.json")
    other.start()
    monitor = monitor_for(system, namespaces=["/cyborg/bt", "/other/bt"])
    try:
        wait_until(lambda: all(source.state is not None
                               for source in monitor.hub.sources.values()), 10, "both trees")
        with local_client(monitor.app) as client, \
                client.websocket_connect("/ws") as socket:
            for namespace in ("/cyborg/bt", "/other/bt", "/cyborg/bt", "/other/bt"):
                sent = watch(socket, namespace)
                version = monitor.hub.sources[namespace].state.version  # type: ignore[union-attr]
                structures = [message for message in sent if message["t"] == "structure"]
                assert [(message["ns"], message["v"]) for message in structures] == [
                    (namespace, version)], f"the page shows another tree: {namespace} again"
                assert sent[-1]["v"] == version
                tick = receive_until(socket, "tick")
                assert (tick["ns"], tick["v"]) == (namespace, version)
            socket.send_json({"t": "refresh"})
            again = receive_until(socket, "structure")
            assert again["ns"] == "/other/bt", "Refresh sends the structure again"
            socket.send_json({"t": "watch", "ns": "/other/bt"})
            receive_until(socket, "watching")
            assert all(message["t"] != "structure"
                       for message in [next_json(socket) for _ in range(3)]), \
                "watching the tree the page shows again needs no structure"
    finally:
        monitor.stop()
        other.destroy()


def test_a_page_that_falls_behind_gets_the_tree_again_instead_of_the_backlog(
        system: System) -> None:
    monitor = monitor_for(system)
    try:
        with local_client(monitor.app) as client, \
                client.websocket_connect("/ws") as socket:
            structure = next(message for message in watch(socket, "/cyborg/bt")
                             if message["t"] == "structure")
            receive_until(socket, "tick")
            page = next(iter(monitor.hub.clients))
            burst = QUEUE_LIMIT + 10

            async def flood() -> None:  # more than its queue holds, before its writer runs
                for number in range(burst):
                    page.send({"t": "filler", "i": number})

            assert client.portal is not None
            client.portal.call(flood)
            fillers = []
            while (message := next_json(socket))["t"] != "structure":
                if message["t"] == "filler":
                    fillers.append(message["i"])
                assert len(fillers) < QUEUE_LIMIT // 2, "the backlog was sent, not dropped"
            assert fillers == list(range(burst - len(fillers), burst)), \
                "only what came after the overflow is sent"
            assert page.dropped >= QUEUE_LIMIT
            assert (message["ns"], message["v"]) == ("/cyborg/bt", structure["v"]), \
                "the tree again, though the page had it"
            assert receive_until(socket, "snapshot")["v"] == structure["v"]
            assert receive_until(socket, "tick")["v"] == structure["v"], "and it follows on"
    finally:
        monitor.stop()
