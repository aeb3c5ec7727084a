"""Relocalising the simulated robot: ``set_pose`` and ``/initialpose`` teleport it.

A pose that is not finite, off the map, or where the body would overlap a wall, a box or a
forbidden area is refused and changes nothing; an accepted one ends the goal (and docking, and
driving by hand) and puts the robot there standing still.
"""

from __future__ import annotations

import logging
import math
import threading
from collections.abc import Iterator

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cyborg.bus import BusConfig, Context, GoalStatus, Node
from cyborg.bus.msgs.builtin_interfaces.msg import Time
from cyborg.bus.msgs.cyborg_msgs.action import MoveToGoal
from cyborg.bus.msgs.cyborg_msgs.msg import GoalWithHeading
from cyborg.bus.msgs.cyborg_msgs.srv import SetPose
from cyborg.bus.msgs.geometry_msgs.msg import Pose2D as Pose2DMessage
from cyborg.bus.msgs.geometry_msgs.msg import PoseWithCovariance, PoseWithCovarianceStamped
from cyborg.bus.msgs.std_msgs.msg import Header
from cyborg.interfaces import robot
from cyborg.interfaces.robot import MoveOutcome
from cyborg.nav.arnl_map import parse_map
from cyborg.nav.geometry import Pose2D
from cyborg.sim.docking import DockState
from cyborg.sim.loop import SimulationLoop
from cyborg.sim.manual import body_touches
from cyborg.sim.navigator import PathState
from cyborg.sim.node import SimulatorNode
from cyborg.sim.simulator import Simulator
from tests.bus.bus_peer import wait_for
from tests.small_maps import room_map

ROOM = room_map(['Goal 2000 3000 0 "" ICON "left"',
                 'GoalWithHeading 8000 3000 90 "" ICON "right"',
                 'Dock 2000 1000 -90 "" ICON "charger"',
                 'Sim.BoxObstacle 0 0 0 "" ICON "" 3000 4500 3400 5500',
                 'ForbiddenArea 0 0 0 "" ICON "" 6500 4500 9500 5500'])


def room(start: Pose2D | str = "left") -> Simulator:
    return Simulator(parse_map(ROOM, "room.map"), start=start)


# ---------------------------------------------------------------------- the simulator alone
@pytest.mark.parametrize(("pose", "reason"), [
    (Pose2D(math.nan, 3.0, 0.0), "is not finite"),
    (Pose2D(2.0, 3.0, math.inf), "is not finite"),
    (Pose2D(12.0, 3.0, 0.0), "is off the map"),
    (Pose2D(3.0, -0.5, 0.0), "is off the map"),
    (Pose2D(5.0, 1.0, 0.0), "would overlap a wall or an obstacle"),  # in the middle wall
    (Pose2D(0.2, 3.0, 0.0), "would overlap a wall or an obstacle"),  # the body, not the centre
    (Pose2D(2.0, 0.3, math.pi / 2), "would overlap a wall or an obstacle"),  # its tail
    (Pose2D(3.2, 5.0, 0.0), "would overlap a wall or an obstacle"),  # the box
    (Pose2D(8.0, 5.0, 0.0), "would overlap a forbidden area"),
    (Pose2D(8.0, 4.35, 0.0), "would overlap a forbidden area"),  # the body, not the centre
])
def test_a_pose_that_does_not_fit_is_refused_and_changes_nothing(pose: Pose2D,
                                                                 reason: str) -> None:
    sim = room()
    assert sim.go_to("right").found
    sim.run(2)
    before = sim.pose
    problem = sim.set_pose(pose)
    assert problem is not None and reason in problem
    assert sim.pose == before and sim.navigator.state is PathState.MOVING_TO_GOAL


def test_set_pose_ends_the_goal_and_puts_the_robot_there_standing_still() -> None:
    sim = room()
    assert sim.go_to("right").found
    sim.run(3)
    assert sim.base.speed > 0.3
    assert sim.set_pose(Pose2D(8.0, 2.0, 2 * math.pi + 0.5)) is None
    pose = sim.pose
    assert (pose.x, pose.y, pose.theta) == pytest.approx((8.0, 2.0, 0.5))  # heading normalised
    assert sim.navigator.state is PathState.ABORTED_PATHPLAN and sim.current_goal is None
    assert (sim.base.speed, sim.base.turn_rate) == (0.0, 0.0)
    ahead = sim.ranges[len(sim.ranges) // 2]  # the scan is taken where the robot now stands
    assert ahead == pytest.approx((10.0 - 8.0) / math.cos(0.5) - 0.267, abs=0.1)
    sim.run(3)
    assert sim.pose.distance_to(Pose2D(8.0, 2.0)) < 1e-9 and sim.base.bumps == 0
    sim.teleop(0.3, 0.0)
    assert sim.set_pose(Pose2D(2.0, 3.0)) is None and sim.teleop_command is None


def test_set_pose_takes_the_robot_off_the_dock() -> None:
    sim = room("charger")
    assert sim.dock()
    assert sim.run_until(lambda: sim.docking.state is DockState.DOCKED, timeout=120)
    assert sim.set_pose(Pose2D(2.0, 3.0)) is None
    assert sim.docking.state is DockState.UNDOCKED and not sim.battery.charging
    sim.run(2)
    assert sim.pose == Pose2D(2.0, 3.0)


@pytest.fixture(scope="module")
def roomy() -> Simulator:
    return room()


@settings(max_examples=200, deadline=None)
@given(x=st.floats(-2, 12), y=st.floats(-2, 8), theta=st.floats(-10, 10))
def test_every_pose_is_refused_or_fits(roomy: Simulator, x: float, y: float,
                                       theta: float) -> None:
    sim = roomy
    before = sim.pose
    problem = sim.set_pose(Pose2D(x, y, theta))
    if problem is not None:
        assert sim.pose == before and "\n" not in problem
        return
    pose = sim.pose
    assert 0.0 <= pose.x <= 10.0 and 0.0 <= pose.y <= 6.0
    assert sim.base.body_clearance(pose) >= 0.0
    assert not body_touches(sim.world, sim.world.forbidden, sim.base, pose)


# ---------------------------------------------------------------------- on the bus
@pytest.fixture
def running() -> Iterator[tuple[Node, Simulator, SimulationLoop]]:
    with Context(BusConfig.isolated()) as context:
        sim = room()
        loop = SimulationLoop(sim, speed=3)
        SimulatorNode(Node("arnl", "/cyborg", context=context), loop)
        loop.start()
        try:
            yield Node("map_page", "/cyborg", context=context), sim, loop
        finally:
            loop.stop()


def initial_pose(pose: Pose2D, frame: str = "map") -> PoseWithCovarianceStamped:
    """The message RViz's "2D Pose Estimate" publishes, with its default covariance."""
    covariance = np.zeros(36)
    covariance[[0, 7, 35]] = (0.25, 0.25, (math.pi / 12) ** 2)
    return PoseWithCovarianceStamped(
        header=Header(stamp=Time(sec=1, nanosec=0), frame_id=frame),
        pose=PoseWithCovariance(pose=pose.to_pose().to_message(), covariance=covariance))


def test_set_pose_on_the_bus_ends_a_running_move_to_goal(
        running: tuple[Node, Simulator, SimulationLoop]) -> None:
    node, sim, loop = running
    goals: list[GoalWithHeading] = []
    robot.CURRENT_GOAL.subscription(node, goals.append)
    moving = threading.Event()
    goal = robot.MOVE_TO_GOAL.client(node).send_goal(
        MoveToGoal.Goal(goal_name="right", pose=Pose2DMessage(x=0.0, y=0.0, theta=0.0),
                        use_heading=False), feedback=lambda _f: moving.set())
    assert moving.wait(10)
    assert wait_for(lambda: bool(goals) and goals[-1].name == "right", 10)
    set_pose = robot.SET_POSE.client(node)
    refused = set_pose.call(SetPose.Request(pose=Pose2DMessage(x=5.0, y=1.0, theta=0.0)),
                            timeout=10)
    assert not refused.success and "would overlap a wall" in refused.message
    assert goals[-1].name == "right"  # a refused pose leaves the goal be
    reply = set_pose.call(SetPose.Request(pose=Pose2DMessage(x=7.0, y=2.0, theta=math.pi / 2)),
                          timeout=10)
    assert reply.success and "(7.00, 2.00) heading 90°" in reply.message
    status, result = goal.result(timeout=10)
    assert (status, result.outcome) == (GoalStatus.ABORTED, int(MoveOutcome.FAILED))
    assert "moved (set_pose)" in result.message
    assert wait_for(lambda: goals[-1].name == "", 10)
    with loop.lock:
        assert sim.pose.distance_to(Pose2D(7.0, 2.0)) < 1e-9
        assert sim.navigator.state is PathState.ABORTED_PATHPLAN


def test_initialpose_as_rviz_publishes_it(running: tuple[Node, Simulator, SimulationLoop],
                                          caplog: pytest.LogCaptureFixture) -> None:
    node, sim, loop = running
    caplog.set_level(logging.INFO, "cyborg.sim")
    publisher = robot.INITIAL_POSE.publisher(node)
    assert wait_for(lambda: publisher.subscription_count() > 0, 10)
    publisher.publish(initial_pose(Pose2D(7.5, 2.5, math.pi / 2)))

    def at(pose: Pose2D) -> bool:
        with loop.lock:
            return (sim.pose.distance_to(pose) < 1e-6
                    and abs(sim.pose.theta - pose.theta) < 1e-6)
    assert wait_for(lambda: at(Pose2D(7.5, 2.5, math.pi / 2)), 10)
    publisher.publish(initial_pose(Pose2D(5.0, 1.0)))  # in the wall
    assert wait_for(lambda: any("/initialpose refused" in r.getMessage()
                                and "would overlap a wall" in r.getMessage()
                                for r in caplog.records), 10)
    caplog.clear()
    publisher.publish(initial_pose(Pose2D(2.0, 3.0), frame="odom"))
    assert wait_for(lambda: any("frame 'odom'" in r.getMessage() for r in caplog.records), 10)
    assert at(Pose2D(7.5, 2.5, math.pi / 2))
