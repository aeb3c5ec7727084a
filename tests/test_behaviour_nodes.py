"""The robot's behaviour nodes against a scripted robot, on a manual clock."""

from __future__ import annotations

import json
import math

import pytest

from cyborg.bt import ERROR, FAILURE, RUNNING, SUCCESS, ManualClock, Status, Tree, loads_tree
from cyborg.nav.geometry import Pose2D
from cyborg.nodes.robot import DockState, MoveOutcome
from tests.builders import N, registry, tree_json
from tests.fake_robot import FakeRobot, robot_tree


def run(tree: Tree, clock: ManualClock, seconds: float, step: float = 0.1) -> list[Status]:
    """Tick every ``step`` seconds for ``seconds``; the statuses returned."""
    statuses: list[Status] = []
    for _ in range(round(seconds / step)):
        statuses.append(tree.tick().status)
        clock.advance(step)
    return statuses


def reason(tree: Tree) -> str:
    """Why the tree's one behaviour node failed."""
    return str(getattr(tree.nodes[1], "reason", ""))


# ---------------------------------------------------------------------------------- MoveTo
def test_move_to_succeeds_with_the_action_and_starts_afresh_each_time() -> None:
    robot, clock = FakeRobot(), ManualClock()
    tree = robot_tree(N("MoveTo", location="home"), robot, clock)
    assert tree.tick().status is RUNNING
    assert [move.goal for move in robot.moves] == ["home"]
    robot.moves[0].finish(MoveOutcome.SUCCEEDED)
    assert tree.tick().status is SUCCESS
    # 2018 defect 19: the old result must not make the next activation succeed at once
    assert tree.tick().status is RUNNING
    assert len(robot.moves) == 2 and not robot.moves[1].done


def test_move_to_succeeds_inside_the_radius_and_stops_the_robot() -> None:
    robot, clock = FakeRobot(), ManualClock()
    tree = robot_tree(N("MoveTo", location="home", radius=0.5), robot, clock)
    tree.tick()
    robot.pose = Pose2D(0.3, 0.3, 2.0)  # heading does not matter for a plain Goal
    assert tree.tick().status is SUCCESS
    assert robot.moves[0].cancelled, "the move is cancelled so the robot stops there"


def test_move_to_a_goal_with_heading_waits_for_the_heading() -> None:
    robot, clock = FakeRobot(), ManualClock()
    tree = robot_tree(N("MoveTo", location="kitchen", radius=0.5), robot, clock)
    tree.tick()
    robot.pose = Pose2D(10.1, 0.0, 0.0)  # there, facing the wrong way
    assert tree.tick().status is RUNNING
    robot.pose = Pose2D(10.1, 0.0, math.pi / 2 - 0.1)
    assert tree.tick().status is SUCCESS


def test_stall_cancels_and_retries_then_fails(caplog: pytest.LogCaptureFixture) -> None:
    robot, clock = FakeRobot(), ManualClock()
    tree = robot_tree(N("MoveTo", location="home", retries=2), robot, clock)
    statuses = run(tree, clock, 9.9)
    assert set(statuses) == {RUNNING} and len(robot.moves) == 1
    run(tree, clock, 0.5)  # no progress at all for 10 s after the start
    assert robot.moves[0].cancelled and len(robot.moves) == 2
    # progress resets the window to 15 s
    robot.moves[1].remaining = 20.0
    run(tree, clock, 5.0)
    robot.moves[1].remaining = 18.0
    run(tree, clock, 14.5)
    assert len(robot.moves) == 2, "15 s after the last progress is allowed"
    run(tree, clock, 1.0)
    assert robot.moves[1].cancelled and len(robot.moves) == 3
    statuses = run(tree, clock, 12.0)
    failed_at = statuses.index(FAILURE) * 0.1  # seconds into this run
    assert 9.0 <= failed_at <= 10.2, "bounded: 1 try + 2 retries, then FAILURE"
    assert len(robot.moves) == 4, "the next activation starts afresh"
    assert all(move.done for move in robot.moves[:3])
    assert "no progress along the path for 10 s; tried 3 times" in caplog.text


def test_a_failed_move_is_retried_but_no_path_fails_at_once() -> None:
    robot, clock = FakeRobot(no_path_to={"kitchen"}), ManualClock()
    tree = robot_tree(N("MoveTo", location="home", retries=1), robot, clock)
    tree.tick()
    robot.moves[0].finish(MoveOutcome.FAILED, "FAILED_MOVE: stuck")
    assert tree.tick().status is RUNNING and len(robot.moves) == 2
    robot.moves[1].finish(MoveOutcome.FAILED, "FAILED_MOVE: stuck")
    assert tree.tick().status is FAILURE
    unreachable = robot_tree(N("MoveTo", location="kitchen"), robot, clock)
    assert unreachable.tick().status is FAILURE
    assert "NO_VALID_PATH" in reason(unreachable)
    unknown = robot_tree(N("MoveTo", location="attic"), robot, clock)
    assert unknown.tick().status is FAILURE
    assert "no goal named 'attic' on the map; goals: Dock, home, kitchen" in \
        reason(unknown)


def test_the_stall_timer_waits_while_the_robot_undocks() -> None:
    robot, clock = FakeRobot(), ManualClock()
    robot.set_battery(90.0, DockState.UNDOCKING)
    tree = robot_tree(N("MoveTo", location="home"), robot, clock)
    run(tree, clock, 30.0)
    assert len(robot.moves) == 1
    robot.set_battery(90.0, DockState.UNDOCKED)
    run(tree, clock, 10.5)
    assert len(robot.moves) == 2


def test_a_halted_move_to_cancels_its_goal() -> None:
    robot, clock = FakeRobot(), ManualClock()
    tree = robot_tree(N("Priority", N("BlackboardCompare", N("Succeeder"), key="low",
                                      value="true"),
                        N("MoveTo", location="home")), robot, clock)
    tree.tick()
    assert not robot.moves[0].cancelled
    tree.blackboard["low"] = True
    assert tree.tick().status is SUCCESS
    assert robot.moves[0].cancelled


def test_nodes_without_a_robot_report_what_is_missing(caplog: pytest.LogCaptureFixture) -> None:
    tree = loads_tree(json.dumps(tree_json(N("MoveTo", location="home"))),
                      registry=registry(), clock=ManualClock())
    assert tree.tick().status is ERROR
    assert "MoveTo needs a robot to act on" in caplog.text


# ---------------------------------------------------------------------------------- battery
def test_check_battery_is_a_latching_guard() -> None:
    robot, clock = FakeRobot(), ManualClock()
    tree = robot_tree(N("Priority", N("CheckBattery", N("Charge", target=95), threshold=25),
                        N("Runner", id="patrol")), robot, clock)
    robot.set_battery(30.0)
    assert tree.tick().active[-1] == "patrol"
    robot.set_battery(24.0)
    assert tree.tick().status is RUNNING and robot.dock_requests == 1
    assert tree.running[0].name == "Charge"
    robot.set_battery(50.0, DockState.DOCKED)  # above the threshold, still charging
    tree.tick()
    assert tree.running[0].name == "Charge"
    robot.set_battery(95.0, DockState.DOCKED)
    assert tree.tick().status is SUCCESS
    assert tree.tick().active[-1] == "patrol"


def test_charge_fails_when_docking_is_refused_or_fails() -> None:
    robot, clock = FakeRobot(can_dock=False), ManualClock()
    robot.set_battery(20.0)
    tree = robot_tree(N("Charge", target=90), robot, clock)
    assert tree.tick().status is FAILURE
    assert "the map has no Dock" in reason(tree)
    robot.can_dock = True
    assert tree.tick().status is RUNNING
    robot.set_battery(20.0, DockState.DOCKING)
    assert tree.tick().status is RUNNING
    robot.set_battery(20.0, DockState.UNDOCKED)  # the drive to the dock gave up
    assert tree.tick().status is FAILURE
    full = robot_tree(N("Charge", target=90), FakeRobot(), clock)
    full.blackboard.resources["robot"].set_battery(91.0)
    assert full.tick().status is SUCCESS


def test_charge_times_out_when_docking_never_starts() -> None:
    robot, clock = FakeRobot(), ManualClock()
    robot.set_battery(20.0)
    tree = robot_tree(N("Charge", target=90), robot, clock)
    statuses = run(tree, clock, 10.5)
    assert statuses.index(FAILURE) in range(100, 103), "fails 10 s after the request"
    assert robot.dock_requests == 2, "then a new activation asks again"


def test_dock_and_undock_wait_for_the_state() -> None:
    robot, clock = FakeRobot(), ManualClock()
    dock = robot_tree(N("Dock"), robot, clock)
    assert dock.tick().status is RUNNING and robot.dock_requests == 1
    robot.set_battery(80.0, DockState.DOCKING)
    assert dock.tick().status is RUNNING and robot.dock_requests == 1
    robot.set_battery(80.0, DockState.DOCKED)
    assert dock.tick().status is SUCCESS
    undock = robot_tree(N("Undock", timeout=5), robot, clock)
    assert undock.tick().status is RUNNING and robot.undock_requests == 1
    assert run(undock, clock, 6.0).index(FAILURE) in range(49, 52)


# ---------------------------------------------------------------------------------- goals
def test_closest_goal_and_distance_write_the_blackboard() -> None:
    robot, clock = FakeRobot(distances={"home": 12.5, "kitchen": 4.0}), ManualClock()
    tree = robot_tree(N("Sequence", N("ClosestGoal"), N("DistanceToGoal", location="home",
                                                        below=20)), robot, clock)
    assert tree.tick().status is SUCCESS
    assert tree.blackboard["closest_goal"] == "kitchen"
    assert tree.blackboard["closest_goal_distance"] == 4.0
    assert tree.blackboard["distance_to_home"] == 12.5
    near = robot_tree(N("DistanceToGoal", location="home", below=10, key="d"), robot, clock)
    assert near.tick().status is FAILURE and near.blackboard["d"] == 12.5
    lost = robot_tree(N("Sequence", N("ClosestGoal"), N("DistanceToGoal", location="Dock")),
                      FakeRobot(), clock)
    assert lost.tick().status is FAILURE and lost.blackboard["closest_goal"] is None


# ---------------------------------------------------------------------------------- compare
@pytest.mark.parametrize(("stored", "value", "equal", "ticks_child"), [
    ("kitchen", "kitchen", True, True),
    ("kitchen", "home", True, False),
    ("kitchen", "home", False, True),
    (3, "3", True, True),
    (2.5, "2.5", True, True),
    (True, "true", True, True),
    (False, "true", True, False),
    (None, "", True, True),
    (None, "x", False, True),
])
def test_blackboard_compare(stored: object, value: str, equal: bool, ticks_child: bool) -> None:
    robot, clock = FakeRobot(), ManualClock()
    tree = robot_tree(N("BlackboardCompare", N("Succeeder"), key="k", value=value,
                        equal=equal), robot, clock)
    if stored is not None:
        tree.blackboard["k"] = stored
    assert tree.tick().status is (SUCCESS if ticks_child else FAILURE)
