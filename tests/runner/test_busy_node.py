"""The tree runner keeps its stop whatever a node does: a node that loops for ever beside a
running MoveTo neither holds up `enable(false)` nor keeps the robot driving, and a tick past its
limit disables the tree and cancels the goal. On an isolated bus with a scripted robot."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from cyborg.bt import NodeRegistry, default_registry
from cyborg.bus import Context, Node
from cyborg.runner.tree_runner import TreeRunnerNode
from tests.bt.test_busy_tick import SPINNING, Spin
from tests.robot.fake_robot import FakeRobot
from tests.runner.test_services import Caller
from tests.runner.test_services import bus as bus  # the fixture
from tests.running_system import wait_until, write_tree


def spin_registry() -> NodeRegistry:
    registry = default_registry()
    registry.add(Spin)
    return registry


@contextmanager
def spinning_runner(bus: Context, folder: Path, robot: FakeRobot,
                    **options: Any) -> Iterator[TreeRunnerNode]:
    """A runner of Parallel(MoveTo home, Spin): the robot drives while Spin spins."""
    SPINNING.clear()
    tree = write_tree(folder, {"name": "Parallel", "children": [
        {"name": "MoveTo", "props": {"location": "home"}}, {"name": "Spin"}]})
    runner = TreeRunnerNode(Node("tree_runner", "/cyborg/bt", context=bus), tree, robot=robot,
                            registry=spin_registry(), **options)
    runner.start()
    try:
        yield runner
    finally:
        runner.destroy()


def test_enable_false_halts_at_once_while_a_node_spins(bus: Context, tmp_path: Path) -> None:
    robot = FakeRobot()
    with spinning_runner(bus, tmp_path, robot, tick_limit=None) as runner:
        assert SPINNING.wait(10.0)
        assert robot.moves and not robot.moves[0].cancelled
        reply, took = Caller(bus).timed("enable", "std_srvs/srv/SetBool", data=False)
        assert took < 0.5, f"enable(false) took {took:.2f} s while a node spun"
        assert reply.success and reply.message == "disabled", reply.message
        assert robot.moves[0].cancelled, "the halt cancelled the robot's goal"
        assert not runner.tree.running


def test_a_tick_past_its_limit_disables_the_tree_and_cancels_the_goal(
        bus: Context, tmp_path: Path) -> None:
    robot = FakeRobot()
    with spinning_runner(bus, tmp_path, robot, tick_limit=0.5) as runner:
        watcher = Node("watcher", "/test", context=bus)
        enabled: list[bool] = []
        watcher.create_subscription("/cyborg/bt/enabled", "std_msgs/msg/Bool",
                                    lambda message: enabled.append(bool(message.data)))
        assert SPINNING.wait(10.0)
        wait_until(lambda: not runner.enabled, timeout=10, what="the overrun to disable the tree")
        wait_until(lambda: enabled[-1:] == [False], timeout=5, what="enabled: false published")
        assert robot.moves[0].cancelled
        assert Caller(bus).call("enable", "std_srvs/srv/SetBool", data=True).success
        wait_until(lambda: len(robot.moves) == 2, timeout=10, what="the tree to run again")
