"""A tree runner given a mode file: the mode on the bus, its transitions, the mode service and
events, the structure and controls following the mode. On an isolated bus, a ManualClock."""

from __future__ import annotations

import json
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from cyborg.bt import Blackboard, ManualClock, TreeLoadError
from cyborg.bus import BusConfig, Context, Node
from cyborg.bus.msgs.cyborg_msgs.msg import (
    BehaviorTree,
    BehaviorTreeStatus,
    ModeState,
    ModeTransition,
)
from cyborg.bus.msgs.cyborg_msgs.srv import SetMode
from cyborg.bus.msgs.std_msgs.msg import String
from cyborg.interfaces import modes, tree_runner
from cyborg.interfaces.modes import ModeAction
from cyborg.modes import SCHEMA, ModeMachine
from cyborg.runner.tree_runner import TreeRunnerNode
from tests.builders import registry
from tests.modes.machines import write_modes, write_project
from tests.modes.test_machine import MISSION, TREES
from tests.running_system import wait_until

NAMESPACE = "/cyborg/bt"


@pytest.fixture
def bus() -> Iterator[Context]:
    context = Context(BusConfig.isolated())
    yield context
    context.close()


class Watcher:
    """Subscribes to the runner's mode topics and structure, as a monitor would."""

    def __init__(self, bus: Context) -> None:
        self.node = Node("watcher", "/test", context=bus)
        self.states: list[ModeState] = []
        self.transitions: list[ModeTransition] = []
        self.structures: list[str] = []
        self.lock = threading.Lock()
        modes.STATE.subscription(self.node, self._keep(self.states), NAMESPACE)
        modes.TRANSITIONS.subscription(self.node, self._keep(self.transitions), NAMESPACE)
        tree_runner.STRUCTURE.subscription(
            self.node, lambda message: self._keep(self.structures)(message.tree), NAMESPACE)
        self.events = modes.EVENTS.publisher(self.node, NAMESPACE)
        self.set_mode = modes.SET_MODE.client(self.node, NAMESPACE)

    def _keep(self, into: list[Any]) -> Any:
        def keep(message: Any) -> None:
            with self.lock:
                into.append(message)
        return keep

    def call(self, action: ModeAction, mode: str = "", reason: str = "") -> Any:
        assert self.set_mode.wait_for_service(10.0)
        request = SetMode.Request(action=int(action), mode=mode, reason=reason)
        return self.set_mode.call(request, timeout=10.0)

    def title_now(self) -> str:
        with self.lock:
            return str(json.loads(self.structures[-1])["title"]) if self.structures else ""


def start_runner(bus: Context, folder: Path, clock: ManualClock) -> TreeRunnerNode:
    write_project(folder, TREES)
    path = write_modes(folder, MISSION)
    runner = TreeRunnerNode(Node("tree_runner", NAMESPACE, context=bus), path,
                            registry=registry(), clock=clock, enabled=False)
    runner.start()
    return runner


def test_the_mode_its_transitions_and_the_structure_follow_on_the_bus(
        bus: Context, tmp_path: Path) -> None:
    clock = ManualClock()
    runner = start_runner(bus, tmp_path, clock)
    watcher = Watcher(bus)
    try:
        machine = runner.ticked
        assert isinstance(machine, ModeMachine)
        wait_until(lambda: bool(watcher.states), 10.0, "the latched mode state")
        first = watcher.states[-1]
        assert first.mode == "normal" and not first.held
        shape = json.loads(first.machine)
        assert shape["schema"] == SCHEMA and shape["initial"] == "normal"
        assert [m["name"] for m in shape["modes"]] == ["normal", "low", "critical", "demo"]
        wait_until(lambda: watcher.title_now() == "patrol", 10.0)

        runner.runner.step()
        machine.globals["battery"] = {"percent": 15}
        runner.runner.step()  # normal -> low after this tick
        assert runner.tree is machine.trees["low"]
        wait_until(lambda: bool(watcher.transitions), 10.0)
        transition = watcher.transitions[-1]
        assert (transition.from_mode, transition.to_mode, transition.trigger,
                transition.number) == ("normal", "low", "condition", 2)
        assert transition.reason == "when battery.percent < 20"
        wait_until(lambda: watcher.states[-1].mode == "low", 10.0)
        wait_until(lambda: watcher.title_now() == "charge", 10.0)

        reply = watcher.call(ModeAction.REQUEST, "critical")
        assert not reply.success and reply.mode == "low"
        reply = watcher.call(ModeAction.HOLD)
        assert reply.success
        wait_until(lambda: watcher.states[-1].held, 10.0, "the hold on the bus")
        reply = watcher.call(ModeAction.FORCE, "critical", "smoke")
        assert reply.success and reply.mode == "critical"
        wait_until(lambda: watcher.transitions[-1].reason == "smoke", 10.0)
        watcher.call(ModeAction.RELEASE)

        sent: list[float] = []

        def event_taken() -> bool:  # published again until heard; once normal, it is refused
            if not sent or time.monotonic() - sent[-1] > 0.5:
                sent.append(time.monotonic())
                watcher.events.publish(String(data="help_arrived"))
            return machine.mode == "normal"

        wait_until(event_taken, 10.0, "the event's transition")
        wait_until(lambda: watcher.transitions[-1].trigger == "event", 10.0)
        wait_until(lambda: watcher.states[-1].transitions == 3, 10.0)
    finally:
        watcher.node.destroy()
        runner.destroy()


def test_a_mode_runner_reloads_mode_files_only(bus: Context, tmp_path: Path) -> None:
    runner = start_runner(bus, tmp_path, ManualClock())
    try:
        with pytest.raises(TreeLoadError, match="reloads only a mode file"):
            runner.reload(tmp_path / "mission.b3.json")
        old = runner.ticked
        tree = runner.reload()
        again = runner.ticked
        assert isinstance(again, ModeMachine) and again is not old
        assert isinstance(old, ModeMachine) and again.globals is not old.globals
        assert tree is again.trees["normal"] is runner.tree
    finally:
        runner.destroy()


def test_globals_survive_a_reload_of_the_mode_file(bus: Context, tmp_path: Path) -> None:
    runner = start_runner(bus, tmp_path, ManualClock())
    try:
        runner.tree.blackboard["battery"] = {"percent": 50}
        runner.reload()
        assert isinstance(runner.ticked, ModeMachine)
        assert runner.ticked.globals["battery"] == {"percent": 50}
        assert isinstance(runner.tree.blackboard, Blackboard)
    finally:
        runner.destroy()


def test_the_structure_message_names_the_current_modes_tree(bus: Context,
                                                            tmp_path: Path) -> None:
    runner = start_runner(bus, tmp_path, ManualClock())
    try:
        assert isinstance(runner.ticked, ModeMachine)
        runner.ticked.force("demo")
        text = json.dumps(runner.tree.structure.to_json())
        assert BehaviorTree(tree=text).tree and json.loads(text)["title"] == "demo"
    finally:
        runner.destroy()


def test_a_failed_reload_republishes_the_mode_with_the_files_problems(
        bus: Context, tmp_path: Path) -> None:
    runner = start_runner(bus, tmp_path, ManualClock())
    watcher = Watcher(bus)
    bad = write_modes(tmp_path, MISSION.replace('tree = "charge"', 'tree = "charging"'),
                      name="bad.modes.toml")
    try:
        wait_until(lambda: bool(watcher.states), 10.0, "the latched mode state")
        assert watcher.states[-1].problems == []
        with pytest.raises(TreeLoadError):
            runner.reload(bad)
        wait_until(lambda: bool(watcher.states[-1].problems), 10.0, "the problems")
        problems = watcher.states[-1].problems
        assert problems[0].startswith(f"{bad}:") and "mode 'low'" in problems[0], problems
        assert watcher.states[-1].mode == "normal", "the machine that loaded runs on"
        runner.reload()
        wait_until(lambda: not watcher.states[-1].problems, 10.0, "problems cleared")
    finally:
        watcher.node.destroy()
        runner.destroy()


def test_a_condition_s_new_tree_goes_out_after_the_status_of_the_tick_before(
        bus: Context, tmp_path: Path) -> None:
    runner = start_runner(bus, tmp_path, ManualClock())
    node = Node("order", "/test", context=bus)
    heard: list[tuple[str, Any]] = []
    tree_runner.STATUS.subscription(node, lambda m: heard.append(("status", m.tick)), NAMESPACE)
    tree_runner.STRUCTURE.subscription(
        node, lambda m: heard.append(("structure", json.loads(m.tree)["title"])), NAMESPACE)
    try:
        machine = runner.ticked
        assert isinstance(machine, ModeMachine)
        wait_until(lambda: ("structure", "patrol") in heard, 10.0, "the first structure")
        wait_until(lambda: _status_heard(runner, heard), 10.0, "a status heard")
        machine.globals["battery"] = {"percent": 15}
        runner.runner.step()  # patrol ticks, then normal -> low
        wait_until(lambda: ("structure", "charge") in heard, 10.0, "the new structure")
        switch = heard.index(("structure", "charge"))
        patrol_ticks = [tick for kind, tick in heard[:switch] if kind == "status"]
        assert patrol_ticks[-1] == machine.trees["normal"].ticks, \
            "the tick that led to the change was heard before the tree entered"
        assert not [entry for entry in heard[switch:] if entry[0] == "status"], \
            "no status of patrol after charge's structure"
    finally:
        node.destroy()
        runner.destroy()


def _status_heard(runner: TreeRunnerNode, heard: list[tuple[str, Any]]) -> bool:
    """Steps the runner until its status is heard (the subscription matched)."""
    if any(kind == "status" for kind, _ in heard):
        return True
    runner.runner.step()
    time.sleep(0.05)
    return False


def test_each_status_names_the_mode_whose_tree_ticked(bus: Context, tmp_path: Path) -> None:
    runner = start_runner(bus, tmp_path, ManualClock())
    watcher = Node("status_watcher", "/test", context=bus)
    statuses: list[BehaviorTreeStatus] = []
    tree_runner.STATUS.subscription(watcher, statuses.append, NAMESPACE)
    try:
        machine = runner.ticked
        assert isinstance(machine, ModeMachine)
        wait_until(lambda: runner._status.subscription_count() > 0, 10.0, "the subscription")
        titles: list[str] = []
        runner.runner.add_listener(lambda snapshot: titles.append(runner.tree_of(snapshot).title))
        runner.runner.step()
        machine.globals["battery"] = {"percent": 15}
        runner.runner.step()  # the normal tree ticks, then the machine goes to low
        runner.runner.step()
        wait_until(lambda: len(statuses) == 3, 10.0, "three statuses")
        assert [status.mode for status in statuses] == ["normal", "normal", "low"]
        assert [status.tick for status in statuses] == [1, 2, 1], "each mode's tree counts"
        assert titles == ["patrol", "patrol", "charge"], "the tree that ticked, not the next"
    finally:
        watcher.destroy()
        runner.destroy()
