"""StopSafely and CallForHelp against a scripted robot, on a manual clock."""

from __future__ import annotations

from typing import Any

import pytest

from cyborg.bt import RUNNING, SUCCESS, ManualClock, TreeLoadError
from cyborg.robot.protocol import RobotError
from tests.builders import N
from tests.robot.fake_robot import FakeRobot, robot_tree


class UnreachableRobot(FakeRobot):
    """While ``gone``, its stop service does not answer: every stop raises."""

    gone = True

    def stop(self) -> None:
        self.stops += 1
        if self.gone:
            raise RobotError("service /cyborg/stop is not available")


def test_stop_safely_stops_the_robot_then_the_call_for_help_repeats_while_it_waits() -> None:
    robot, clock = FakeRobot(), ManualClock(100.0)
    tree = robot_tree(N("MemSequence", N("StopSafely"),
                        N("CallForHelp", reason="battery critical", every=30.0)), robot, clock)
    assert tree.tick().status is RUNNING
    assert robot.stops == 1 and robot.help_calls == [("battery critical", 100.0)]
    for _ in range(29):
        clock.advance(1.0)
        assert tree.tick().status is RUNNING
    assert len(robot.help_calls) == 1, "not again before `every` seconds"
    clock.advance(1.0)
    tree.tick()
    assert robot.help_calls[-1] == ("battery critical", 130.0)
    assert robot.stops == 1, "the MemSequence stopped once and waits in the call"
    assert robot.moves == [], "a stopped robot is not sent anywhere"


def test_a_halted_call_for_help_calls_at_once_when_it_starts_again() -> None:
    robot, clock = FakeRobot(), ManualClock()
    tree = robot_tree(N("CallForHelp", every=60.0), robot, clock)
    tree.tick()
    tree.halt()
    clock.advance(1.0)
    tree.tick()
    assert [time for _, time in robot.help_calls] == [0.0, 1.0]
    assert robot.help_calls[0][0] == "the robot needs help", "the default reason"


def test_the_call_says_which_goal_the_robot_is_near_when_the_blackboard_knows() -> None:
    robot, clock = FakeRobot(), ManualClock()
    tree = robot_tree(N("CallForHelp", reason="stopped", every=10.0, near="closest_goal"),
                      robot, clock)
    tree.tick()
    tree.blackboard["closest_goal"] = "Library"
    clock.advance(10.0)
    tree.tick()
    tree.blackboard["closest_goal"] = None  # no goal reachable
    clock.advance(10.0)
    tree.tick()
    assert [reason for reason, _ in robot.help_calls] == [
        "stopped", "stopped; near Library", "stopped"]


def test_stop_safely_asks_again_while_the_robot_does_not_answer() -> None:
    robot, clock = UnreachableRobot(), ManualClock()
    tree = robot_tree(N("StopSafely"), robot, clock)
    assert tree.tick().status is RUNNING and tree.tick().status is RUNNING
    assert robot.stops == 2
    robot.gone = False  # the service is back
    assert tree.tick().status is SUCCESS


@pytest.mark.parametrize(("props", "field"), [({"reason": " "}, "reason"),
                                              ({"every": 0}, "every"),
                                              ({"every": -5}, "every")])
def test_bad_call_for_help_properties_are_load_errors(props: dict[str, Any],
                                                      field: str) -> None:
    with pytest.raises(TreeLoadError, match=field):
        robot_tree(N("CallForHelp", **props), FakeRobot())
