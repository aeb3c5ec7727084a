"""The tree runner on the bus, driving the simulated robot: topics, enable, control, reload."""

from __future__ import annotations

import json
import math
import os
import sys
import threading
import time
from concurrent.futures import Future
from pathlib import Path
from typing import Any

import pytest

from cyborg.bus import Node, Qos, new_message
from cyborg.sim.docking import DockState
from tests.runner.test_services import refused_or_timed_out, release_fifo
from tests.running_system import running_system, wait_until, write_tree
from tests.small_maps import room_map, write

FAILER_MODULE = """
from cyborg.bt import Action, Status, register

@register
class Explode(Action):
    def tick(self) -> Status:
        raise RuntimeError("boom: a faulty sensor driver")
"""


HANGING_MODULE = """
import threading

from cyborg.bt import Action, Status, register

GATE = threading.Event()

@register
class HangsWhileBuilt(Action):
    def __init__(self) -> None:
        GATE.wait(30.0)  # a model that takes forever to load

    def tick(self) -> Status:
        return Status.RUNNING
"""


@pytest.fixture
def patrol(shared: Path) -> Path:
    return shared / "trees" / "patrol_recharge.b3.json"


@pytest.fixture
def amroffice(shared: Path) -> Path:
    return shared / "maps" / "AMROffice.map"


def _listen(node: Node, topic: str, kind: str, latched: bool = False) -> list[Any]:
    got: list[Any] = []
    node.create_subscription(topic, kind, got.append, Qos.latched() if latched else None)
    return got


def test_topics_and_enable_halts_and_restarts_the_robot(patrol: Path, amroffice: Path) -> None:
    with running_system(amroffice, patrol, speed=10, start="Dock") as system:
        client = system.client
        structure = _listen(client, "/cyborg/bt/behavior_tree", "cyborg_msgs/msg/BehaviorTree",
                            latched=True)
        updates = _listen(client, "/cyborg/bt/behavior_tree_updates",
                          "cyborg_msgs/msg/BehaviorTreeNodes", latched=True)
        enabled = _listen(client, "/cyborg/bt/enabled", "std_msgs/msg/Bool", latched=True)
        status = _listen(client, "/cyborg/bt/status", "cyborg_msgs/msg/BehaviorTreeStatus")
        wait_until(lambda: structure and updates and enabled and len(status) > 3,
                   what="the runner's topics")
        tree = json.loads(structure[-1].tree)
        assert tree == system.runner.tree.structure.to_json()
        assert enabled[-1].data is True
        room1 = system.uid("MoveTo room1")
        wait_until(lambda: updates[-1].ids and updates[-1].ids[-1] == room1, what="MoveTo room1")
        last = status[-1]
        assert last.tick > status[0].tick and last.status == 3  # RUNNING
        assert room1 in list(last.visited_ids) and len(last.visited_statuses) == len(
            last.visited_ids)
        assert last.stamp.sec + last.stamp.nanosec * 1e-9 <= system.sim.time + 1.0
        wait_until(lambda: system.sim.base.speed > 0.2, what="the robot driving")
        # disable: the tree halts, MoveTo cancels its goal, the robot stops
        reply = system.call("/cyborg/bt/enable", "std_srvs/srv/SetBool", data=False)
        assert (reply.success, reply.message) == (True, "disabled")
        wait_until(lambda: enabled[-1].data is False and list(updates[-1].ids) == [],
                   what="disabled flag and an empty active path")
        wait_until(lambda: abs(system.sim.base.speed) < 0.01, what="the robot to stop")
        ticks = system.runner.tree.ticks
        pose = system.sim.pose
        threading.Event().wait(0.5)
        assert system.runner.tree.ticks == ticks, "a disabled tree does not tick"
        assert system.sim.pose.distance_to(pose) < 0.05
        # enable: the tree starts afresh and the robot drives to room1 again
        assert system.call("/cyborg/bt/enable", "std_srvs/srv/SetBool", data=True).success
        wait_until(lambda: enabled[-1].data is True and system.sim.base.speed > 0.2,
                   what="the robot driving again")
        assert updates[-1].ids[-1] == room1


def test_control_services_and_hooks_released_when_the_client_leaves(
        patrol: Path, amroffice: Path) -> None:
    with running_system(amroffice, patrol, speed=10, start="Dock") as system:
        hooks = _listen(system.client, "/cyborg/bt/hooks", "cyborg_msgs/msg/BehaviorTreeHooks",
                        latched=True)
        monitor = Node("monitor", "/test", context=system.context)
        control = monitor.create_client("/cyborg/bt/control", "cyborg_msgs/srv/ControlNode")

        def ask(**fields: Any) -> Any:
            return control.call(new_message(monitor.types, "cyborg_msgs/srv/ControlNode_Request",
                                            fields), timeout=10)
        patrol_id = system.uid("Repeat -1x")
        bad = ask(node_id="nope", action=1, status=2)
        assert not bad.success and "no node with id 'nope'" in bad.message
        bad = ask(node_id=patrol_id, action=1, status=3)
        assert not bad.success and "returns success or failure, not running" in bad.message
        # disable the patrol subtree: the robot stops driving, the tree keeps ticking
        reply = ask(node_id=patrol_id, action=1, status=2)
        assert reply.success, reply.message
        wait_until(lambda: hooks and list(hooks[-1].node_ids) == [patrol_id], what="hooks")
        assert hooks[-1].owners[0] == "/test/monitor" and list(hooks[-1].actions) == [1]
        wait_until(lambda: abs(system.sim.base.speed) < 0.01, what="the robot to stop")
        ticks = system.runner.tree.ticks
        wait_until(lambda: system.runner.tree.ticks > ticks + 5, what="ticks")
        # a kept hook survives its client; a plain one goes with it
        kept = ask(node_id=system.uid("Priority"), action=3, keep=True)
        assert kept.success
        wait_until(lambda: hooks[-1].paused_at == system.uid("Priority"), what="breakpoint")
        blackboard = json.loads(system.call("/cyborg/bt/get_blackboard",
                                            "cyborg_msgs/srv/GetBlackboard").json)
        assert set(blackboard) == {"global", "trees", "nodes"}
        assert system.call("/cyborg/bt/step", "std_srvs/srv/Trigger").success
        wait_until(lambda: hooks[-1].paused_at not in ("", system.uid("Priority")),
                   what="a step to the next node")
        assert ask(node_id=system.uid("Priority"), action=0).success
        assert system.call("/cyborg/bt/resume", "std_srvs/srv/Trigger").success
        monitor.destroy()  # the client leaves the bus: its hooks are released
        wait_until(lambda: list(hooks[-1].node_ids) == [] and hooks[-1].paused_at == "",
                   timeout=10, what="hooks released")
        wait_until(lambda: system.sim.base.speed > 0.2, what="the robot driving again")


def test_reload_rejects_a_bad_file_and_keeps_running(patrol: Path, amroffice: Path,
                                                     tmp_path: Path) -> None:
    with running_system(amroffice, patrol, speed=10, start="Dock") as system:
        structure = _listen(system.client, "/cyborg/bt/behavior_tree",
                            "cyborg_msgs/msg/BehaviorTree", latched=True)
        wait_until(lambda: structure, what="structure")
        broken = tmp_path / "broken.b3.json"
        broken.write_text('{"version": "0.3.0", "trees": [\n  {"id": 1,}\n]}\n')
        reply = system.call("/cyborg/bt/reload", "cyborg_msgs/srv/ReloadTree", path=str(broken))
        assert not reply.success and f"{broken}:2" in reply.message
        ticks = system.runner.tree.ticks
        wait_until(lambda: system.runner.tree.ticks > ticks + 5, what="the old tree ticking")
        assert system.runner.path == patrol
        small = write_tree(tmp_path, {"name": "MoveTo", "props": {"location": "room2"}})
        reply = system.call("/cyborg/bt/reload", "cyborg_msgs/srv/ReloadTree", path=str(small))
        assert reply.success, reply.message
        wait_until(lambda: json.loads(structure[-1].tree)["title"] == "Test tree",
                   what="the new structure")
        wait_until(lambda: system.sim.navigator.goal is not None and math.hypot(
            system.sim.navigator.goal.x - system.sim.map.goal("room2").x,
            system.sim.navigator.goal.y - system.sim.map.goal("room2").y) < 0.01,
            what="the robot heading to room2")
        again = system.call("/cyborg/bt/reload", "cyborg_msgs/srv/ReloadTree", path="")
        assert again.success and str(small) in again.message


def test_enable_stops_the_robot_at_once_while_a_reload_hangs(
        patrol: Path, amroffice: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A reload that never ends must not hold the stop button: enable(false) is answered within
    a second and the robot stops; the reload is answered with a timeout error and the patrol
    tree stays loaded. The load hangs in a node's constructor (a FIFO used to do it; the loader
    now refuses one at once, so it is tried too)."""
    (tmp_path / "hanging_nodes.py").write_text(HANGING_MODULE)
    monkeypatch.syspath_prepend(str(tmp_path))
    hangs = write_tree(tmp_path, {"name": "HangsWhileBuilt"}, "hangs.b3.json")
    fifo = tmp_path / "never.b3.json"
    os.mkfifo(fifo)
    with running_system(amroffice, patrol, speed=10, start="Dock",
                        registry_modules=["hanging_nodes"]) as system:
        gate = sys.modules["hanging_nodes"].GATE
        system.runner.node.parameters.set({"reload_timeout": 2.0})
        wait_until(lambda: system.sim.base.speed > 0.2, what="the robot driving")
        reload = system.client.create_client("/cyborg/bt/reload", "cyborg_msgs/srv/ReloadTree")

        def reload_async(path: Path) -> Future[Any]:
            return reload.call_async(new_message(system.client.types,
                                                 "cyborg_msgs/srv/ReloadTree_Request",
                                                 {"path": str(path)}), timeout=10)
        try:
            answer = reload_async(fifo).result(8)
            assert not answer.success and refused_or_timed_out(answer.message, "2 s"), \
                answer.message
            pending = reload_async(hangs)
            threading.Event().wait(0.3)  # the reload has started and hangs
            started = time.monotonic()
            reply = system.call("/cyborg/bt/enable", "std_srvs/srv/SetBool", data=False)
            took = time.monotonic() - started
            assert reply.success and took < 1.0, f"enable answered after {took:.2f} s"
            wait_until(lambda: abs(system.sim.base.speed) < 0.01, timeout=5,
                       what="the robot to stop")
            answer = pending.result(8)
            assert not answer.success and "did not finish within 2 s" in answer.message
            assert system.runner.path == patrol
        finally:
            gate.set()
            release_fifo(fifo)


def test_unreachable_goal_makes_move_to_fail_not_hang(tmp_path: Path) -> None:
    arnl = write(tmp_path, "room.map", room_map([
        'Goal 2000 3000 0 "" ICON "start"', 'Goal 5000 1000 0 "" ICON "in the wall"']))
    tree = write_tree(tmp_path, {"name": "MoveTo", "props": {"location": "in the wall"}})
    with running_system(arnl, tree, speed=10, start="start") as system:
        status = _listen(system.client, "/cyborg/bt/status", "cyborg_msgs/msg/BehaviorTreeStatus")
        wait_until(lambda: any(message.status == 2 for message in status), timeout=20,
                   what="MoveTo to fail")
        assert system.sim.pose.distance_to(system.sim.map.goal("start")) < 0.05  # type: ignore[arg-type]


def test_a_raising_node_does_not_stop_the_tree(tmp_path: Path, amroffice: Path,
                                               monkeypatch: pytest.MonkeyPatch,
                                               caplog: pytest.LogCaptureFixture) -> None:
    (tmp_path / "faulty_nodes.py").write_text(FAILER_MODULE)
    monkeypatch.syspath_prepend(str(tmp_path))
    tree = write_tree(tmp_path, {"name": "MemSequence", "children": [
        {"name": "MoveTo", "props": {"location": "room1", "radius": 0.5}},
        {"name": "Explode"},
        {"name": "MoveTo", "props": {"location": "room2", "radius": 0.5}}]})
    with running_system(amroffice, tree, speed=20, start="Dock",
                        registry_modules=["faulty_nodes"]) as system:
        status = _listen(system.client, "/cyborg/bt/status", "cyborg_msgs/msg/BehaviorTreeStatus")
        wait_until(lambda: any(message.status == 4 for message in status), timeout=60,
                   what="the ERROR from the raising node")
        errors = sum(message.status == 4 for message in status)
        wait_until(lambda: sum(message.status == 4 for message in status) > errors + 3,
                   what="the tree to keep ticking")
        raised = [record for record in caplog.records if "raised in tick" in record.getMessage()]
        assert len(raised) == 1, "logged once, with its traceback; repeats are counted"
        # the faulty node can be switched off from outside and the mission goes on
        explode = system.uid("Explode")
        reply = system.call("/cyborg/bt/control", "cyborg_msgs/srv/ControlNode",
                            node_id=explode, action=1, status=1, keep=True)
        assert reply.success
        room2 = system.sim.map.goal("room2")
        wait_until(lambda: system.sim.pose.distance_to(room2) < 0.5, timeout=60,  # type: ignore[arg-type]
                   what="the robot reaching room2")
        assert system.sim.docking.state is DockState.UNDOCKED
