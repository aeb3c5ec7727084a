"""Driving the simulated robot by hand: ``cmd_vel``, its limits, its safety and its deadman.

First the simulator alone (:meth:`Simulator.teleop`): a robot driven at a wall, a box or into a
corner slows and stops short of it, without a bump. Then on the bus: the deadman counts wall
time, a twist that is not finite is ignored, a command ends a running ``move_to_goal`` and
``current_goal`` shows the goal while it runs.
"""

from __future__ import annotations

import logging
import math
import threading
from collections.abc import Callable, Iterator
from typing import Any

import pytest

from cyborg.bus import BusConfig, Context, GoalStatus, Node
from cyborg.bus.msgs.cyborg_msgs.action import MoveToGoal
from cyborg.bus.msgs.cyborg_msgs.msg import GoalWithHeading
from cyborg.bus.msgs.geometry_msgs.msg import Pose2D as Pose2DMessage
from cyborg.bus.msgs.geometry_msgs.msg import Twist, Vector3
from cyborg.interfaces import robot
from cyborg.interfaces.robot import TELEOP_MAX_SPEED, TELEOP_MAX_TURN_RATE, MoveOutcome
from cyborg.nav.arnl_map import parse_map
from cyborg.nav.geometry import Pose2D
from cyborg.sim.docking import DockState
from cyborg.sim.loop import SimulationLoop
from cyborg.sim.navigator import PathState
from cyborg.sim.node import SimulatorNode
from cyborg.sim.simulator import Simulator
from tests.bus.bus_peer import wait_for
from tests.small_maps import room_map

ROOM = room_map(['Goal 2000 3000 0 "" ICON "left"',
                 'GoalWithHeading 8000 3000 90 "far side" ICON "right"',
                 'Dock 2000 1000 -90 "" ICON "charger"',
                 'Sim.BoxObstacle 0 0 0 "" ICON "" 3000 4500 3400 5500'])


def room(start: Pose2D | str = "left") -> Simulator:
    return Simulator(parse_map(ROOM, "room.map"), start=start)


def path_state(sim: Simulator) -> PathState:
    return sim.navigator.state


def dock_state(sim: Simulator) -> DockState:
    return sim.docking.state


def twist(speed: float, turn_rate: float = 0.0) -> Twist:
    return Twist(linear=Vector3(x=speed, y=0.0, z=0.0),
                 angular=Vector3(x=0.0, y=0.0, z=turn_rate))


# ---------------------------------------------------------------------- the simulator alone
@pytest.mark.parametrize(("start", "command"), [
    (Pose2D(2.0, 3.0, math.pi), (1.0, 0.0)),  # forwards at the left wall (asked too fast)
    (Pose2D(2.0, 3.0, 0.0), (-0.5, 0.0)),  # backwards into it: the laser does not look back
    (Pose2D(2.0, 2.0, -3 * math.pi / 4), (0.5, 0.0)),  # into the corner
    (Pose2D(3.2, 3.0, math.pi / 2), (0.5, 0.0)),  # at the box
    (Pose2D(2.0, 4.9, 0.0), (0.5, 0.0)),  # along the wall into the box's side
])
def test_driving_at_a_wall_or_a_box_stops_short_of_it(start: Pose2D,
                                                      command: tuple[float, float]) -> None:
    sim = room(start)
    sim.teleop(*command)
    gaps = []
    for _ in range(round(30 * sim.settings.physics_rate)):
        sim.step()
        gaps.append(sim.base.body_clearance(sim.pose))
        assert abs(sim.base.speed) <= TELEOP_MAX_SPEED + 1e-9
    assert sim.base.bumps == 0 and not sim.base.bumpers.any
    assert min(gaps) >= 0.0
    assert sim.base.speed == 0.0 and gaps[-1] < 0.35  # it went as far as it safely could
    assert sim.pose.distance_to(start) > 0.5


def test_an_arc_into_a_wall_turns_along_it_without_touching_it() -> None:
    """Where the arc asked for would touch the wall, the motion check brakes and turns less,
    then on the spot, until the arc is clear again: the robot slides along the wall."""
    sim = room(Pose2D(2.0, 3.0, math.pi))
    sim.teleop(0.5, 0.15)
    lowest = math.inf
    for _ in range(round(30 * sim.settings.physics_rate)):
        sim.step()
        lowest = min(lowest, sim.base.body_clearance(sim.pose))
    assert sim.base.bumps == 0 and lowest >= 0.0
    assert lowest < 0.1 and sim.base.odometer > 5.0


def test_commands_are_clamped_and_must_be_finite() -> None:
    sim = room(Pose2D(2.0, 3.0, 0.0))
    assert sim.teleop(5.0, -9.0) == (TELEOP_MAX_SPEED, -TELEOP_MAX_TURN_RATE)
    assert sim.teleop(-0.2, 0.1) == (-0.2, 0.1)
    for bad in (math.nan, math.inf, -math.inf):
        with pytest.raises(ValueError, match="finite"):
            sim.teleop(bad, 0.0)
    assert sim.teleop_command == (-0.2, 0.1)  # a refused command changes nothing


def test_a_command_cancels_the_goal_and_zero_stops() -> None:
    sim = room()
    assert sim.go_to("right").found
    sim.run(3)
    assert path_state(sim) is PathState.MOVING_TO_GOAL and sim.base.speed > 0.3
    assert sim.current_goal is not None and sim.current_goal.name == "right"
    sim.teleop(0.0, 0.0)
    assert path_state(sim) is PathState.ABORTED_PATHPLAN and sim.current_goal is None
    sim.run(3)
    assert sim.base.speed == 0.0 and sim.base.turn_rate == 0.0
    assert sim.go_to("right").found and sim.teleop_command is None  # a goal takes over again


def test_a_moving_command_drives_off_the_dock_and_zero_leaves_it_docked() -> None:
    sim = room("charger")
    assert sim.dock()
    assert sim.run_until(lambda: sim.docking.state is DockState.DOCKED, timeout=120)
    sim.teleop(0.0, 0.0)
    sim.run(1)
    assert dock_state(sim) is DockState.DOCKED and sim.battery.charging
    sim.teleop(-0.3, 0.0)
    assert dock_state(sim) is DockState.UNDOCKED and not sim.battery.charging
    before = sim.pose
    sim.run(2)
    assert sim.pose.distance_to(before) > 0.2 and sim.base.bumps == 0


# ---------------------------------------------------------------------- on the bus
class Robot:
    """A simulator on the bus with a wall clock the test moves, and a client node."""

    def __init__(self, context: Context, speed: float) -> None:
        self.wall = 0.0
        self.sim = room()
        self.loop = SimulationLoop(self.sim, speed=speed)
        SimulatorNode(Node("arnl", "/cyborg", context=context), self.loop,
                      clock=lambda: self.wall)
        self.client = Node("operator", "/cyborg", context=context)
        self.cmd_vel = robot.CMD_VEL.publisher(self.client)
        self.goals: list[GoalWithHeading] = []
        self._arrived = threading.Condition()
        robot.CURRENT_GOAL.subscription(self.client, self._take)
        assert wait_for(lambda: self.cmd_vel.subscription_count() > 0, 10)

    def _take(self, message: GoalWithHeading) -> None:
        with self._arrived:
            self.goals.append(message)
            self._arrived.notify_all()

    def goal_named(self, name: str) -> GoalWithHeading:
        with self._arrived:
            assert self._arrived.wait_for(
                lambda: bool(self.goals) and self.goals[-1].name == name, 10), \
                [goal.name for goal in self.goals]
            return self.goals[-1]

    def read(self, what: Callable[[Simulator], Any]) -> Any:
        """``what(simulator)``, read under the simulation's lock."""
        with self.loop.lock:
            return what(self.sim)


@pytest.fixture
def bus() -> Iterator[Context]:
    with Context(BusConfig.isolated()) as context:
        yield context


def started(context: Context, speed: float) -> Robot:
    robot_ = Robot(context, speed)
    robot_.loop.start()
    return robot_


def test_the_deadman_counts_wall_time_not_simulated_time(bus: Context) -> None:
    """At 10 times real time, simulated seconds pass without a stop; the robot stops once
    0.5 s of the (test's) wall clock pass without a command."""
    it = started(bus, speed=10)
    try:
        with it.loop.lock:
            it.sim.set_pose(Pose2D(7.5, 0.8, math.pi / 2))  # 4.8 m to the wall ahead: 30 s
        it.cmd_vel.publish(twist(0.15))
        assert wait_for(lambda: it.read(lambda sim: sim.base.speed) > 0.1, 10)
        at = it.read(lambda sim: sim.time)
        # 3 simulated seconds, the same wall-clock instant: no stop yet
        assert wait_for(lambda: it.read(lambda sim: sim.time) > at + 3.0, 10)
        assert it.read(lambda sim: (sim.teleop_command, sim.base.speed > 0.1)) == (
            (0.15, 0.0), True)
        it.wall = 0.6
        assert wait_for(lambda: it.read(lambda sim: sim.teleop_command) is None, 10)
        assert wait_for(lambda: it.read(lambda sim: sim.base.speed) == 0.0, 10)
        assert it.read(lambda sim: sim.base.bumps) == 0
    finally:
        it.loop.stop()


def test_a_twist_that_is_not_finite_is_ignored_with_one_warning(
        bus: Context, caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.WARNING, "cyborg.sim")
    it = started(bus, speed=2)
    try:
        assert wait_for(lambda: it.read(lambda sim: sim.time) > 0.2, 10)
        with it.loop.lock:
            assert it.sim.go_to("right").found
        for bad in (twist(math.nan), twist(0.0, math.inf), twist(-math.inf, 0.1)):
            it.cmd_vel.publish(bad)
        done = Twist(linear=Vector3(x=0.0, y=math.nan, z=0.0), angular=Vector3(x=0.0, y=0.0, z=0.0))
        it.cmd_vel.publish(done)
        assert wait_for(lambda: any("not finite" in r.getMessage() for r in caplog.records), 10)
        threading.Event().wait(0.3)
        warnings = [r for r in caplog.records if "not finite" in r.getMessage()]
        assert len(warnings) == 1 and "/cyborg/cmd_vel" in warnings[0].getMessage()
        assert it.read(lambda sim: sim.teleop_command) is None
        # the goal runs on (or is reached, on a slow machine), not ended by the bad twists
        assert it.read(lambda sim: sim.navigator.state) in (PathState.MOVING_TO_GOAL,
                                                             PathState.REACHED_GOAL)
    finally:
        it.loop.stop()


def test_cmd_vel_ends_a_running_move_to_goal_and_current_goal_follows(bus: Context) -> None:
    it = started(bus, speed=3)
    try:
        assert it.goal_named("").position.x == 0.0  # latched at the start: no goal
        action = robot.MOVE_TO_GOAL.client(it.client)
        moving = threading.Event()
        nowhere = Pose2DMessage(x=0.0, y=0.0, theta=0.0)
        goal = action.send_goal(MoveToGoal.Goal(goal_name="right", pose=nowhere,
                                                use_heading=False),
                                feedback=lambda _f: moving.set())
        assert moving.wait(10)
        shown = it.goal_named("right")
        assert (shown.position.x, shown.position.y) == pytest.approx((8.0, 3.0))
        assert shown.has_heading and shown.comment == "far side"
        it.cmd_vel.publish(twist(0.0))
        status, result = goal.result(timeout=10)
        assert (status, result.outcome) == (GoalStatus.ABORTED, int(MoveOutcome.FAILED))
        assert "driven by hand (cmd_vel)" in result.message
        it.goal_named("")
        assert wait_for(lambda: it.read(lambda sim: sim.base.speed) == 0.0, 10)
        # a pose goal is named by its coordinates
        goal = action.send_goal(MoveToGoal.Goal(goal_name="", pose=Pose2DMessage(
            x=3.0, y=2.0, theta=0.0), use_heading=False))
        shown = it.goal_named("(3.00, 2.00)")
        assert not shown.has_heading
        status, result = goal.result(timeout=30)
        assert (status, result.outcome) == (GoalStatus.SUCCEEDED, int(MoveOutcome.SUCCEEDED))
        it.goal_named("")
    finally:
        it.loop.stop()
