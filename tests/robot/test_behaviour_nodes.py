"""The robot's behaviour nodes against a scripted robot, on a manual clock."""

from __future__ import annotations

import json
import logging
import math
from typing import Any

import pytest

from cyborg.bt import (
    ERROR,
    FAILURE,
    RUNNING,
    SUCCESS,
    ManualClock,
    Status,
    Tree,
    TreeLoadError,
    loads_tree,
)
from cyborg.nav.geometry import Pose2D
from cyborg.robot import move_to
from cyborg.robot.protocol import DockState, MoveOutcome
from cyborg.robot.rate_limited_log import RateLimitedLog
from tests.builders import N, registry, tree_json
from tests.robot.fake_robot import FakeRobot, robot_tree


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


def test_a_robot_waiting_for_someone_to_make_way_is_not_stalled() -> None:
    robot, clock = FakeRobot(), ManualClock()
    tree = robot_tree(N("MoveTo", location="home", retries=0), robot, clock)
    tick = tree.tick()
    robot.moves[0].remaining = 20.0
    run(tree, clock, 1.0)
    robot.moves[0].waiting = True  # a person stands in the only way
    statuses = run(tree, clock, 60.0)
    assert set(statuses) == {RUNNING} and not robot.moves[0].cancelled
    robot.moves[0].waiting = False  # the way is open again, yet nothing moves
    statuses = run(tree, clock, 16.0)
    assert FAILURE in statuses and robot.moves[0].cancelled, "the stall timer runs again"
    assert tick.status is RUNNING


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


def attempts_over(tree: Tree, clock: ManualClock, robot: FakeRobot, seconds: float,
                  step: float = 0.25) -> list[float]:
    """Tick every ``step`` s (exact in binary) for ``seconds``; the times at which the node
    tried to send the robot."""
    times: list[float] = []
    for _ in range(round(seconds / step)):
        before = robot.send_attempts
        tree.tick()
        if robot.send_attempts > before:
            times.append(clock.now())
        clock.advance(step)
    return times


def test_move_to_backs_off_while_the_action_server_is_gone(
        caplog: pytest.LogCaptureFixture) -> None:
    """The simulator was killed: move_to fails at once. The patrol must not retry every tick
    and log a warning each time (727 warnings in 75 s)."""
    caplog.set_level(logging.INFO, "cyborg.robot")
    robot, clock = FakeRobot(reachable=False), ManualClock()
    tree = robot_tree(N("Repeater", N("MemSequence", N("MoveTo", location="home"),
                                      N("Wait", milliseconds=2000),
                                      N("MoveTo", location="kitchen")), maxLoop=-1),
                      robot, clock)
    attempts = attempts_over(tree, clock, robot, 75.0)
    assert attempts == [0.0, 2.0, 6.0, 14.0, 30.0, 60.0], "2 s doubling, up to 30 s"
    warnings = [record for record in caplog.records if record.levelno >= logging.WARNING]
    assert 1 <= len(warnings) <= 3, [record.getMessage() for record in warnings]
    assert len(caplog.records) <= 10
    assert "tried 3 times" in warnings[0].getMessage()
    assert "not available" in warnings[0].getMessage()
    # the simulator is back: the next try (at most the cap later) gets through
    robot.reachable = True
    assert attempts_over(tree, clock, robot, 20.0) == [90.0]
    assert robot.moves and not robot.moves[0].done
    assert tree.tick().status is RUNNING


def test_move_to_waits_running_between_tries_then_fails_and_keeps_its_back_off() -> None:
    robot, clock = FakeRobot(reachable=False), ManualClock()
    tree = robot_tree(N("MoveTo", location="home", retries=1, retryDelay=1,
                        retryDelayMax=8), robot, clock)
    assert run(tree, clock, 1.0, 0.25) == [RUNNING] * 4 and robot.send_attempts == 1
    assert "trying again in 1 s" in reason(tree)
    assert tree.tick().status is FAILURE and robot.send_attempts == 2, "1 try + 1 retry"
    assert "tried 2 times" in reason(tree) and "not available" in reason(tree)
    # the next activation does not hammer the server: it waits out the back-off first (2 s)
    clock.advance(0.25)
    assert run(tree, clock, 1.75, 0.25) == [RUNNING] * 7 and robot.send_attempts == 2
    assert "waiting" in reason(tree)
    robot.reachable = True
    assert tree.tick().status is RUNNING and robot.send_attempts == 3 and robot.moves


def test_the_back_off_doubles_up_to_its_cap_and_starts_again_after_a_send() -> None:
    robot, clock = FakeRobot(reachable=False), ManualClock()
    tree = robot_tree(N("MoveTo", location="home", retries=100, retryDelay=1,
                        retryDelayMax=4), robot, clock)
    assert attempts_over(tree, clock, robot, 19.5) == [0.0, 1.0, 3.0, 7.0, 11.0, 15.0, 19.0]
    robot.reachable = True
    assert attempts_over(tree, clock, robot, 4.0) == [23.0]
    robot.reachable = False
    robot.moves[0].finish(MoveOutcome.FAILED, "FAILED_MOVE: stuck")  # retried at once...
    assert attempts_over(tree, clock, robot, 3.5) == [23.5, 24.5, 26.5], "...back off from 1 s"


def test_an_unreachable_map_service_backs_off_too() -> None:
    robot, clock = FakeRobot(reachable=False), ManualClock()
    tree = robot_tree(N("MoveTo", location="attic"), robot, clock)  # not cached: asks again
    assert tree.tick().status is RUNNING
    assert "get_available_goals is not available" in reason(tree)


@pytest.mark.parametrize("props", [{"retryDelay": 0}, {"retryDelay": -1},
                                   {"retryDelayMax": 0.5}, {"retryDelay": "soon"}])
def test_bad_back_off_properties_are_load_errors(props: dict[str, Any]) -> None:
    with pytest.raises(TreeLoadError, match="retryDelay"):
        robot_tree(N("MoveTo", location="home", **props), FakeRobot())


def test_a_missing_goal_in_a_loop_is_logged_once_per_interval(
        caplog: pytest.LogCaptureFixture) -> None:
    robot, clock = FakeRobot(), ManualClock()
    tree = robot_tree(N("Repeater", N("MoveTo", location="attic"), maxLoop=-1), robot, clock)
    run(tree, clock, 20.0)  # fails every tick: nothing to back off from, the goal is not there
    warnings = [record.getMessage() for record in caplog.records
                if record.levelno >= logging.WARNING]
    assert 1 <= len(warnings) <= 4, warnings
    assert "no goal named 'attic'" in warnings[0]


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


def test_a_refused_dock_in_a_loop_is_logged_once_per_interval(
        caplog: pytest.LogCaptureFixture) -> None:
    robot, clock = FakeRobot(can_dock=False), ManualClock()
    robot.set_battery(20.0)
    tree = robot_tree(N("Priority", N("CheckBattery", N("Charge", target=95), threshold=25),
                        N("Runner")), robot, clock)
    run(tree, clock, 20.0)
    assert robot.dock_requests == 200, "the guard asks every tick"
    warnings = [record.getMessage() for record in caplog.records
                if record.levelno >= logging.WARNING]
    assert 1 <= len(warnings) <= 2 and "the map has no Dock" in warnings[0], warnings


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


# ---------------------------------------------------------------------------------- time jumps
class JumpingClock(ManualClock):
    """A manual clock that can be set back, as a restarted simulation's /clock is."""

    def jump_to(self, seconds: float) -> None:
        self._now = seconds


def test_stall_detection_after_the_clock_went_back() -> None:
    """After a backward jump MoveTo's stall window counts from the jump, not from the old
    start (which would leave a stalled robot unnoticed for as long as the jump)."""
    robot, clock = FakeRobot(), JumpingClock(1000.0)
    tree = robot_tree(N("MoveTo", location="home", retries=2), robot, clock)
    run(tree, clock, 1.0)
    clock.jump_to(100.0)
    run(tree, clock, 10.5)
    assert robot.moves[0].cancelled and len(robot.moves) == 2


def test_charge_and_undock_time_out_after_the_clock_went_back() -> None:
    robot, clock = FakeRobot(), JumpingClock(1000.0)
    robot.set_battery(20.0)
    charge = robot_tree(N("Charge", target=90), robot, clock)
    run(charge, clock, 1.0)
    clock.jump_to(100.0)
    assert FAILURE in run(charge, clock, 10.5)
    robot = FakeRobot()
    robot.set_battery(80.0, DockState.DOCKED)
    undock = robot_tree(N("Undock", timeout=5), robot, clock)
    run(undock, clock, 1.0)
    clock.jump_to(10.0)
    assert FAILURE in run(undock, clock, 5.5)


def test_a_goal_blocked_again_and_again_is_reported_once_then_summarised(
        caplog: pytest.LogCaptureFixture, monkeypatch: pytest.MonkeyPatch) -> None:
    robot, clock = FakeRobot(), ManualClock()
    # the failures come a simulated minute apart: well past the rate limit's interval
    monkeypatch.setattr(move_to, "limited", RateLimitedLog(move_to.log, clock=clock.now))
    tree = robot_tree(N("Repeater", N("MoveTo", location="home", retries=0), maxLoop=-1),
                      robot, clock)
    caplog.set_level(logging.INFO, "cyborg.robot")
    blocked = "WAITING: waited 60 s for the objects in the way to move"
    for _ in range(20):  # a patrol back at a goal whose way stays blocked, 20 times
        tree.tick()
        robot.moves[-1].finish(MoveOutcome.FAILED, blocked)
        tree.tick()
        clock.advance(60.0)
    warnings = [record.getMessage() for record in caplog.records
                if record.levelno >= logging.WARNING]
    assert len(warnings) == 1 and blocked in warnings[0], warnings
    tree.tick()
    robot.moves[-1].finish(MoveOutcome.SUCCEEDED)
    tree.tick()
    said = [record.getMessage() for record in caplog.records if record.levelno == logging.INFO]
    assert any("failed 19 more times in 1200 s alike, then reached the goal" in line
               and blocked in line for line in said), said
