"""The monitor's Modes panel, server side (cyborg.monitor.mode_link and mode_source): a runner's
mode machine is found beside its tree and sent to the pages watching it as ``modes``; its
transitions are kept; the tree view switches with the mode without the statuses of the tree
left; the seat's holder forces, requests and holds, every bad field refused by name, pages
without the seat refused; a mode file that fails to reload and a machine that cannot be drawn
are shown as problems; the messages are rate-limited. (What the monitor makes of a machine's
JSON: test_mode_source.py.)"""

from __future__ import annotations

import asyncio
import itertools
import json
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

from cyborg.bt import TreeLoadError
from cyborg.bus import BusConfig, Context, Node
from cyborg.modes import ModeMachine
from cyborg.monitor import Monitor
from cyborg.monitor.mode_link import MODES_INTERVAL, REASON_LIMIT, ModeLink
from cyborg.monitor.seat import NOT_HOLDER, VIEW_ONLY, ControlSeat
from cyborg.runner.tree_runner import TreeRunnerNode
from tests.monitor.mode_runs import NAMESPACE, start_runner
from tests.monitor.monitor_protocol import local_client, next_json, receive_until
from tests.running_system import wait_until


@pytest.fixture
def bus() -> Iterator[Context]:
    with Context(BusConfig.isolated()) as context:
        yield context


@pytest.fixture
def monitor(bus: Context) -> Iterator[Monitor]:
    monitor = Monitor(Node("monitor", "/cyborg", context=bus), namespaces=[NAMESPACE])
    try:
        yield monitor
    finally:
        monitor.stop()


@pytest.fixture
def runner(bus: Context, tmp_path: Path) -> Iterator[TreeRunnerNode]:
    runner = start_runner(bus, tmp_path)
    try:
        yield runner
    finally:
        runner.destroy()


def machine_of_runner(runner: TreeRunnerNode) -> ModeMachine:
    machine = runner.ticked
    assert isinstance(machine, ModeMachine)
    return machine


def _modes(socket: Any, accept: Callable[[dict[str, Any] | None], bool],
           limit: int = 400) -> dict[str, Any] | None:
    """The next ``modes`` message's content that ``accept`` takes."""
    for _ in range(limit):
        message = receive_until(socket, "modes")
        if accept(message["modes"]):
            found: dict[str, Any] | None = message["modes"]
            return found
    raise AssertionError("no such modes message")


def _answer(socket: Any, command: dict[str, Any]) -> dict[str, Any]:
    socket.send_json(command)
    while True:
        message = next_json(socket)
        if message["t"] in ("result", "error") and message["req"] == command.get("req"):
            return message


def _holding_the_seat(socket: Any) -> None:
    socket.send_json({"t": "hello"})
    receive_until(socket, "seat")
    assert _answer(socket, {"t": "claim", "req": 0})["ok"] is True
    socket.send_json({"t": "watch", "ns": NAMESPACE})


def test_the_machine_goes_to_watching_pages_with_its_transitions(
        monitor: Monitor, runner: TreeRunnerNode) -> None:
    machine = machine_of_runner(runner)
    with local_client(monitor.app) as client, client.websocket_connect("/ws") as socket:
        socket.send_json({"t": "watch", "ns": NAMESPACE})
        shown = _modes(socket, lambda m: m is not None)
        assert shown is not None
        assert shown["mode"] == "normal" and shown["held"] is False and shown["problems"] == []
        drawn = shown["machine"]
        assert drawn["initial"] == "normal"
        assert [(m["name"], m["title"]) for m in drawn["modes"]] == [
            ("normal", "Patrol"), ("low", "Go charge"), ("critical", "Stop and call"),
            ("demo", "Demo")]
        assert drawn["modes"][3]["max_time"] == 60 and drawn["modes"][3]["then"] == "normal"
        first = drawn["transitions"][0]
        assert (first["from"], first["to"], first["trigger"], first["when"]) == (
            ["*"], "critical", "condition", "battery.percent < 5 && !charging")
        assert [t["trigger"] for t in drawn["transitions"]] == [
            "condition", "condition", "condition", "event", "request"]

        runner.runner.step()
        machine.globals["battery"] = {"percent": 15}
        runner.runner.step()  # normal -> low after this tick
        low = _modes(socket, lambda m: m is not None and m["mode"] == "low")
        assert low is not None and low["count"] == 1
        wait_until(lambda: bool(monitor.hub.modes.sources[NAMESPACE].recent), 20)
        later = _modes(socket, lambda m: m is not None and m["recent"])
        assert later is not None
        assert later["recent"][-1] == {"from": "normal", "to": "low", "number": 2,
                                       "reason": "when battery.percent < 20",
                                       "trigger": "condition", "time": 0.0}


def test_the_tree_view_follows_the_mode_without_the_statuses_of_the_tree_left(
        monitor: Monitor, runner: TreeRunnerNode) -> None:
    machine = machine_of_runner(runner)
    wait_until(lambda: monitor.hub.sources[NAMESPACE].state is not None, 20, "the structure")
    for _ in range(3):  # Patrol's act runs: RUNNING on ids that Go charge's tree shares
        runner.runner.step()
    patrol = monitor.hub.sources[NAMESPACE].state
    assert patrol is not None
    wait_until(lambda: patrol.tick == 3, 20, "Patrol's ticks")
    machine.globals["battery"] = {"percent": 15}
    runner.runner.step()  # Patrol's 4th tick, then normal -> low
    runner.runner.step()  # Go charge's first tick
    source = monitor.hub.sources[NAMESPACE]

    def charging() -> bool:
        state = source.state
        return state is not None and state.structure.get("title") == "Go charge" \
            and state.tick == 1
    wait_until(charging, 20, "Go charge's tree and its first tick")
    state = source.state
    assert state is not None
    assert [entry[0] for entry in state.history_json()] == [1], \
        "only the entered tree's own tick; none of the tree left"


@pytest.mark.parametrize(("command", "field"), [
    ({"t": "mode_force"}, "mode"),
    ({"t": "mode_force", "mode": 3}, "mode"),
    ({"t": "mode_force", "mode": None}, "mode"),
    ({"t": "mode_force", "mode": "Critical"}, "mode"),
    ({"t": "mode_force", "mode": "*"}, "mode"),
    ({"t": "mode_request", "mode": ["demo"]}, "mode"),
    ({"t": "mode_force", "mode": "critical", "reason": 5}, "reason"),
    ({"t": "mode_force", "mode": "critical", "reason": None}, "reason"),
    ({"t": "mode_force", "mode": "critical", "reason": "x" * (REASON_LIMIT + 1)}, "reason"),
    ({"t": "mode_hold"}, "held"),
    ({"t": "mode_hold", "held": "yes"}, "held"),
    ({"t": "mode_hold", "held": 1}, "held"),
    ({"t": "mode_force", "mode": "critical", "ns": "/**"}, "ns"),
    ({"t": "mode_force", "mode": "critical", "ns": 7}, "ns"),
    ({"t": "mode_hold", "held": True, "ns": "/elsewhere/bt"}, "ns"),
])
def test_every_bad_field_is_refused_naming_it(monitor: Monitor, runner: TreeRunnerNode,
                                              command: dict[str, Any], field: str) -> None:
    machine = machine_of_runner(runner)
    with local_client(monitor.app) as client, client.websocket_connect("/ws") as socket:
        _holding_the_seat(socket)
        _modes(socket, lambda m: m is not None)
        refused = _answer(socket, {**command, "req": 7})
        assert refused["ok"] is False and refused["field"] == field, refused
        assert f"field {field}: " in refused["message"], refused["message"]
        assert refused["command"] == command["t"]
        assert machine.mode == "normal" and not machine.held, "nothing reached the machine"


def test_the_holder_forces_requests_and_holds_and_every_page_sees_it(
        monitor: Monitor, runner: TreeRunnerNode) -> None:
    machine = machine_of_runner(runner)
    with local_client(monitor.app) as client, \
            client.websocket_connect("/ws") as holder, client.websocket_connect("/ws") as other:
        _holding_the_seat(holder)
        other.send_json({"t": "watch", "ns": NAMESPACE})
        _modes(other, lambda m: m is not None)

        held = _answer(holder, {"t": "mode_hold", "held": True, "req": 1})
        assert held["ok"] is True and held["command"] == "mode_hold", held
        assert _modes(other, lambda m: m is not None and m["held"]) is not None
        forced = _answer(holder, {"t": "mode_force", "mode": "critical", "reason": "smoke",
                                  "req": 2})
        assert forced["ok"] is True and "critical" in forced["message"], forced
        seen = _modes(other, lambda m: m is not None and m["mode"] == "critical"
                      and m["recent"])
        assert seen is not None and seen["held"] is True, "a hold stays on the forced mode"
        assert seen["recent"][-1]["trigger"] == "force"
        assert seen["recent"][-1]["reason"] == "smoke"

        assert _answer(holder, {"t": "mode_force", "mode": "normal", "req": 3})["ok"]
        refused = _answer(holder, {"t": "mode_request", "mode": "demo", "req": 4})
        assert refused["ok"] is False and refused["field"] is None
        assert "held by the operator" in refused["message"], "the machine's own reason"
        assert _answer(holder, {"t": "mode_hold", "held": False, "req": 5})["ok"] is True
        assert _modes(other, lambda m: m is not None and not m["held"]) is not None
        taken = _answer(holder, {"t": "mode_request", "mode": "demo", "req": 6})
        assert taken["ok"] is True, taken
        refused = _answer(holder, {"t": "mode_request", "mode": "low", "req": 8})
        assert refused["ok"] is False and "no transition lets a request" in refused["message"]
        assert machine.mode == "demo" and not machine.held


def test_pages_without_the_seat_are_refused(monitor: Monitor, runner: TreeRunnerNode) -> None:
    machine = machine_of_runner(runner)
    with local_client(monitor.app) as client, \
            client.websocket_connect("/ws") as holder, client.websocket_connect("/ws") as other, \
            local_client(monitor.app, peer="192.0.2.7") as remote, \
            remote.websocket_connect("/ws") as viewer:
        _holding_the_seat(holder)
        for page, why in ((other, NOT_HOLDER), (viewer, VIEW_ONLY)):
            page.send_json({"t": "watch", "ns": NAMESPACE})
            assert _modes(page, lambda m: m is not None) is not None, "shown to every page"
            commands: list[dict[str, Any]] = [{"t": "mode_force", "mode": "critical"},
                                              {"t": "mode_request", "mode": "demo"},
                                              {"t": "mode_hold", "held": True}]
            for number, command in enumerate(commands):
                refused = _answer(page, {**command, "req": 20 + number})
                assert refused["ok"] is False and why in refused["message"], refused
        assert machine.mode == "normal" and not machine.held


def test_a_failed_reload_shows_its_problems_beside_the_running_machine(
        monitor: Monitor, runner: TreeRunnerNode, tmp_path: Path) -> None:
    bad = tmp_path / "bad.modes.toml"
    bad.write_text('project = "mission.b3.json"\ninitial = "normal"\n[modes.normal]\n'
                   'tree = "Go charging"\n')
    with local_client(monitor.app) as client, client.websocket_connect("/ws") as socket:
        socket.send_json({"t": "watch", "ns": NAMESPACE})
        _modes(socket, lambda m: m is not None)
        with pytest.raises(TreeLoadError):
            runner.reload(bad)
        shown = _modes(socket, lambda m: m is not None and m["problems"])
        assert shown is not None and shown["mode"] == "normal"
        assert len(shown["machine"]["modes"]) == 4, "the machine still running is drawn"
        assert any(line.startswith(f"{bad}:4") and "mode 'normal'" in line
                   and "Go charging" in line for line in shown["problems"]), shown["problems"]
        runner.reload()
        assert _modes(socket, lambda m: m is not None and not m["problems"]) is not None


def test_a_runner_without_modes_is_null_and_a_machine_that_leaves_too(
        bus: Context, monitor: Monitor, tmp_path: Path) -> None:
    with local_client(monitor.app) as client, client.websocket_connect("/ws") as socket:
        socket.send_json({"t": "watch", "ns": NAMESPACE})
        assert receive_until(socket, "modes")["modes"] is None, "none before a runner"
        runner = start_runner(bus, tmp_path)
        try:
            assert _modes(socket, lambda m: m is not None) is not None
        finally:
            runner.destroy()
        assert _modes(socket, lambda m: m is None) is None
        wait_until(lambda: NAMESPACE not in monitor.hub.modes.sources, 20, "the machine let go")


class _Page:
    """A page watching ``/t/bt`` that notes what it is sent, and when."""

    watching = "/t/bt"

    def __init__(self) -> None:
        self.sent: list[tuple[float, dict[str, Any]]] = []

    def send(self, message: str) -> None:
        self.sent.append((time.monotonic(), json.loads(message)))


class _Machine:
    alive, view = True, None

    def __init__(self) -> None:
        self.number = 0

    def wire(self) -> dict[str, Any]:
        return {"count": self.number}

    def destroy(self) -> None:
        """Nothing to withdraw."""


def test_a_burst_of_changes_goes_out_at_most_four_times_a_second_the_newest_last() -> None:
    page, machine = _Page(), _Machine()
    trees: dict[str, Any] = {"/t/bt": object()}
    link = ModeLink([page], ControlSeat(None), trees)  # type: ignore[list-item]
    link.sources["/t/bt"] = machine  # type: ignore[assignment]

    async def burst() -> None:
        link.attach(asyncio.get_running_loop())
        for number in range(1, 201):
            machine.number = number
            link.notify("/t/bt")
            await asyncio.sleep(0.002)
        deadline = time.monotonic() + 10 * MODES_INTERVAL + 5
        while page.sent[-1][1]["modes"]["count"] != 200 and time.monotonic() < deadline:
            await asyncio.sleep(0.02)

    asyncio.run(burst())
    counts = [message["modes"]["count"] for _, message in page.sent]
    assert counts[0] == 1 and counts[-1] == 200, counts
    assert counts == sorted(set(counts)), "each sent once, in order"
    gaps = [later - earlier for (earlier, _), (later, _) in itertools.pairwise(page.sent)]
    assert min(gaps) >= MODES_INTERVAL - 1e-3, gaps
    assert len(page.sent) < 200 / 2, "the burst was merged"

