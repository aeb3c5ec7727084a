"""The robot's services: BatteryWatch and ClosestGoal write the blackboard from the robot."""

from __future__ import annotations

import logging
import math
from concurrent.futures import Future

import pytest

from cyborg.bt import Blackboard, ManualClock, Tree, default_service_registry, loads_tree
from cyborg.robot.protocol import ROBOT, DockState, RobotError
from tests.builders import N, registry, tree_json
from tests.robot.fake_robot import FakeRobot


def _tree(declaration: str, robot: FakeRobot | None) -> Tree:
    import json

    text = json.dumps(tree_json(N("Sequence", N("Runner"), id="top", services=declaration)))
    resources = {} if robot is None else {ROBOT: robot}
    return loads_tree(text, registry=registry(), clock=ManualClock(),
                      services=default_service_registry(entry_points=False),
                      blackboard=Blackboard(resources=resources))


def _advance(tree: Tree, seconds: float) -> None:
    clock = tree.clock
    assert isinstance(clock, ManualClock)
    clock.advance(seconds)
    tree.tick()


def test_battery_watch_writes_the_reading_as_a_dict_and_flat_keys() -> None:
    robot = FakeRobot()
    robot.set_battery(80.0)
    tree = _tree("BatteryWatch(low=30, run_on_activation=true)", robot)
    tree.tick()
    board = tree.blackboard
    assert board["battery"] == {"percent": 80.0, "charging": False, "docked": False,
                                "dock_state": "undocked", "low": False, "time": 0.0}
    assert board["battery_percent"] == 80.0 and board["battery_low"] is False
    robot.set_battery(20.0, DockState.DOCKED)
    _advance(tree, 0.5)
    assert board["battery_percent"] == 80.0  # not due yet: one run a second by default
    _advance(tree, 0.5)
    assert board["battery"]["docked"] is True and board["battery"]["charging"] is True
    assert board["battery_percent"] == 20.0 and board["battery_low"] is True
    snapshot = tree.last
    assert snapshot is not None and snapshot.services is not None
    assert snapshot.services[0].wrote["battery_low"] == "True"


def test_battery_watch_writes_nothing_before_the_first_reading() -> None:
    robot = FakeRobot(battery=None)
    tree = _tree("BatteryWatch(key=power, run_on_activation=true)", robot)
    tree.tick()
    assert "power" not in tree.blackboard and "power_low" not in tree.blackboard


@pytest.mark.parametrize("declaration", ["BatteryWatch(low=101)", "BatteryWatch(key='')",
                                         "ClosestGoal(key='')", "BatteryWatch(period=1)"])
def test_bad_options_are_load_errors(declaration: str) -> None:
    from cyborg.bt import TreeLoadError

    with pytest.raises(TreeLoadError, match="services, column"):
        _tree(declaration, FakeRobot())


def test_closest_goal_writes_the_nearest_goal_and_its_distance() -> None:
    robot = FakeRobot(distances={"home": 7.0, "kitchen": 3.5})
    tree = _tree("ClosestGoal(key=closest, interval=1, run_on_activation=true)", robot)
    tree.tick()
    assert tree.blackboard["closest"] == "kitchen"
    assert tree.blackboard["closest_distance"] == 3.5
    robot.distances = {"home": math.inf}
    _advance(tree, 1.0)
    assert tree.blackboard["closest"] is None
    assert tree.blackboard["closest_distance"] == math.inf


def test_closest_goal_writes_a_slow_answer_at_the_next_run() -> None:
    asked: list[Future[tuple[str, float]]] = []

    class SlowRobot(FakeRobot):
        def closest_goal(self) -> Future[tuple[str, float]]:
            future: Future[tuple[str, float]] = Future()
            asked.append(future)
            return future

    tree = _tree("ClosestGoal(interval=1, run_on_activation=true)", SlowRobot())
    tree.tick()
    assert len(asked) == 1 and "closest_goal" not in tree.blackboard
    asked[0].set_result(("home", 2.0))
    _advance(tree, 1.0)
    assert tree.blackboard["closest_goal"] == "home" and len(asked) == 2
    _advance(tree, 1.0)  # the second question is still open: nothing new is asked
    assert len(asked) == 2


def test_closest_goal_keeps_going_when_the_robot_cannot_answer(
        caplog: pytest.LogCaptureFixture) -> None:
    class GoneRobot(FakeRobot):
        def closest_goal(self) -> Future[tuple[str, float]]:
            raise RobotError("service /cyborg/nav/get_closest_goal is not available")

    tree = _tree("ClosestGoal(interval=1, run_on_activation=true)", GoneRobot())
    with caplog.at_level(logging.WARNING, logger="cyborg.robot"):
        tree.tick()
        _advance(tree, 1.0)
    assert "get_closest_goal is not available" in caplog.text
    snapshot = tree.last
    assert snapshot is not None and snapshot.services is not None
    assert snapshot.services[0].active and snapshot.services[0].error is None


def test_a_tree_without_a_robot_names_the_composite_and_stops_the_service(
        caplog: pytest.LogCaptureFixture) -> None:
    tree = _tree("BatteryWatch(run_on_activation=true)", None)
    assert [node.uid for node in tree.missing_resources()[ROBOT]] == ["top"]
    with caplog.at_level(logging.ERROR, logger="cyborg.bt"):
        snapshot = tree.tick()
    assert "service BatteryWatch on composite top" in caplog.text
    assert snapshot.services is not None and not snapshot.services[0].active
    assert "needs a robot to watch" in (snapshot.services[0].error or "")


def test_without_a_robot_stubs_leave_the_services_out_with_a_warning(
        caplog: pytest.LogCaptureFixture) -> None:
    import json

    from cyborg.bt import RUNNING

    text = json.dumps(tree_json(N("Sequence", N("Runner"), id="top",
                                  services="BatteryWatch; ClosestGoal")))
    plain = loads_tree(text, registry=registry(),
                       services=default_service_registry(entry_points=False))
    assert [node.uid for node in plain.missing_resources()[ROBOT]] == ["top"]  # named once
    with caplog.at_level(logging.WARNING, logger="cyborg.bt"):
        stubbed = loads_tree(text, registry=registry(), stub_missing=RUNNING,
                             services=default_service_registry(entry_points=False))
    assert stubbed.services is None and stubbed.missing_resources() == {}
    assert "service 'ClosestGoal' needs a 'robot' resource and this tree has none" in caplog.text
