"""The tree beside the robot on the map: the label of the node its tree runs now goes to the
page in ``rs`` as ``node``, and the goal it drives to (``current_goal``) as ``goal``, each only
when it changed; a goal that cannot be drawn is a warning."""

from __future__ import annotations

import json
import math
from pathlib import Path

from cyborg.bus import Node
from cyborg.bus.msgs.cyborg_msgs.msg import GoalWithHeading
from cyborg.bus.msgs.geometry_msgs.msg import Pose2D
from cyborg.monitor.robot_wire import goal_wire
from cyborg.monitor.tree_state import TreeState
from cyborg.runner.tree_runner import TreeRunnerNode
from tests.monitor.monitor_protocol import local_client
from tests.monitor.robot_messages import goal, pose
from tests.monitor.test_robot_protocol import (
    _followed,
    _gather,
    _map_on,
    _until,
    robot_bus,
)
from tests.running_system import wait_until


def _state() -> TreeState:
    def node(uid: str, label: str, *children: dict[str, object]) -> dict[str, object]:
        return {"id": uid, "name": uid.title(), "label": label, "children": list(children)}

    return TreeState(json.dumps({"root": node("root", "", node("par", "Parallel", node(
        "move", "MoveTo room1"), node("seq", "Sequence", node("wait", "Wait 2000ms"))),
        node("idle", "Idle"))}))


def test_the_running_node_is_the_deepest_of_the_active_path() -> None:
    state = _state()
    assert state.running_label() == "", "nothing runs before the first tick"
    state.apply_active(["root", "par", "move"])
    assert state.running_label() == "MoveTo room1"
    state.apply_active(["root", "par", "move", "seq", "wait"])
    assert state.running_label() == "Wait 2000ms", "the deepest of two running branches"
    state.apply_active(["root", "par", "seq"])
    assert state.running_label() == "Sequence", "a composite whose child did not run"
    state.apply_active(["root"])
    assert state.running_label() == "Root", "no label: the name"


def test_a_goal_becomes_a_name_a_pose_and_whether_it_has_a_heading() -> None:
    assert goal_wire(goal("room1", 1.2344, -2.0, 7.0)) == (
        {"name": "room1", "p": [1.234, -2.0, round(math.remainder(7.0, math.tau), 3)],
         "h": True}, [])
    assert goal_wire(goal("", 1.0, 2.0)) == (None, []), "an empty name: no goal"
    assert goal_wire(goal("(3.00, 4.00)", 3.0, 4.0, heading=False))[0] == {
        "name": "(3.00, 4.00)", "p": [3.0, 4.0, 0.5], "h": False}


def test_a_goal_that_cannot_be_drawn_is_a_warning() -> None:
    assert goal_wire(goal("room1", math.nan, 2.0)) == (
        None, ["goal: 'room1' not shown: x is nan"])
    far, warnings = goal_wire(goal("far", 2e4, 0.0))
    assert far is None and warnings[0].startswith("goal: 'far' not shown: (20000, 0) is more")
    long_name = GoalWithHeading(name="g" * 500, comment="",
                                position=Pose2D(x=1.0, y=1.0, theta=0.0), has_heading=True)
    clipped, warnings = goal_wire(long_name)
    assert clipped is not None and len(clipped["name"]) == 200
    assert warnings == ["goal: name clipped to 200 characters"]


def test_the_current_goal_goes_to_the_page_when_it_changes() -> None:
    with robot_bus() as (monitor, fake), local_client(monitor.app) as client, \
            client.websocket_connect("/ws") as socket:
        _map_on(socket)
        _followed(monitor, fake)
        fake.pose.publish(pose(1.0, 2.0, 0.5))
        _until(socket, "rs")
        fake.goal.publish(goal("room1", 4.0, 5.0, 1.0))
        sent = _until(socket, "rs", lambda m: "goal" in m)
        assert sent["goal"] == {"name": "room1", "p": [4.0, 5.0, 1.0], "h": True}
        fake.pose.publish(pose(1.5, 2.0, 0.5))
        assert "goal" not in _until(socket, "rs", lambda m: m["p"][0] == 1.5), "sent once"
        with client.websocket_connect("/ws") as other:  # a page that starts gets it at once
            _map_on(other)
            assert _until(other, "rs")["goal"] == sent["goal"]
        fake.goal.publish(goal("room2", math.inf, 1.0))
        got = _gather(socket, {"robot_warn": None, "rs": lambda m: "goal" in m})
        assert got["robot_warn"]["kind"] == "goal" and got["robot_warn"]["message"] == (
            "goal: 'room2' not shown: x is inf")
        assert got["rs"]["goal"] is None, "the goal that cannot be drawn is none"
        fake.goal.publish(goal("room3", 1.0, 1.0, 0.0, heading=False))
        assert _until(socket, "rs", lambda m: "goal" in m)["goal"]["h"] is False
        fake.goal.publish(goal(""))
        assert _until(socket, "rs", lambda m: "goal" in m)["goal"] is None


def test_the_running_node_of_the_robots_tree_goes_to_the_page(shared: Path) -> None:
    with robot_bus() as (monitor, fake), local_client(monitor.app) as client, \
            client.websocket_connect("/ws") as socket:
        _map_on(socket)
        _followed(monitor, fake)
        fake.pose.publish(pose(1.0, 2.0, 0.5))
        first = _until(socket, "rs")
        assert "node" not in first, "no tree runs: no node"
        runner = TreeRunnerNode(Node("tree_runner", "/robot1/bt", context=monitor.node.context),
                                shared / "trees" / "stock_nodes.tree.json")
        runner.start()
        try:
            named = _until(socket, "rs", lambda m: m.get("node"))
            assert named["node"] == "Wait 50ms", "the one node of this tree that runs"
        finally:
            runner.destroy()
        assert _until(socket, "rs", lambda m: m.get("node") == "")["ns"] == "/robot1", \
            "the runner left: nothing runs"
        wait_until(lambda: monitor.hub.robot_hub.robots["/robot1"].node == "", 5.0)
