"""Several simulated robots on one map: distinct free starts, robots that see each other on the
laser and never overlap, one clock and a namespace (and frames) per robot on the bus."""

from __future__ import annotations

import math
from importlib.resources import files
from pathlib import Path

import numpy as np
import pytest

from cyborg.bus import BusConfig, Context, Node
from cyborg.bus.component import LaunchError, NodeSpec
from cyborg.bus.msgs.sensor_msgs.msg import LaserScan
from cyborg.bus.msgs.tf2_msgs.msg import TFMessage
from cyborg.bus.wire import EntityKind
from cyborg.interfaces import robot
from cyborg.nav.arnl_map import parse_map, read_map
from cyborg.nav.geometry import Pose2D
from cyborg.nav.planner import Planner
from cyborg.sim import component
from cyborg.sim.bodies import polygon_gap
from cyborg.sim.fleet import START_SPACING, Fleet, choose_starts, robot_loops
from cyborg.sim.loop import PacedLoop
from cyborg.sim.manual import placement_problem
from cyborg.sim.simulator import Simulator
from tests.running_system import wait_until
from tests.small_maps import room_map

CAMPUS = Path(str(files("cyborg.app").joinpath("data", "campus.map")))


def test_robots_start_apart_on_free_reachable_poses_off_the_goals() -> None:
    campus = read_map(CAMPUS)
    fleet = Fleet(campus, 4)
    sims = fleet.simulators
    assert sims[0].pose == Fleet(campus, 1).simulators[0].pose, "the first starts as one alone"
    for index, sim in enumerate(sims):
        assert placement_problem(sim.pose, sim.bounds, sim.base, sim.world) is None
        for other in sims[index + 1:]:
            assert math.hypot(sim.pose.x - other.pose.x,
                              sim.pose.y - other.pose.y) >= START_SPACING - 1e-9
        if index:
            assert sim.planner.plan(sims[0].pose, sim.pose).found, "reachable from the first"
            assert all(math.hypot(sim.pose.x - goal.x, sim.pose.y - goal.y) >= 1.0
                       for goal in campus.goals())


def test_a_map_too_small_for_the_fleet_says_how_many_fit() -> None:
    room = parse_map(room_map([]))
    with pytest.raises(ValueError, match=r"robots: .* has room for (\d+) robots .* not 40"):
        choose_starts(room, Planner(room), 40, Pose2D(1.0, 1.0))
    with pytest.raises(ValueError, match="robots: a fleet has 1 to 16 robots, not 0"):
        Fleet(room, 0)


def test_a_robot_sees_another_on_its_laser() -> None:
    fleet = Fleet(parse_map(room_map([])), 2, start=Pose2D(1.0, 3.0, 0.0))
    looking, seen = fleet.simulators
    alone = looking.laser.scan(1.0, 3.0, 0.0)
    assert seen.set_pose(Pose2D(3.5, 3.0, math.pi / 2)) is None  # across its way, 2.5 m ahead
    while looking.scans < 3:
        fleet.step()
    ahead = int(np.argmin(np.abs(looking.angles)))
    mount = looking.laser.spec.mount_x
    # the other's side is 0.24 m before its centre: 3.5 - 0.24 - (1.0 + mount)
    assert looking.ranges[ahead] == pytest.approx(3.5 - 0.24 - 1.0 - mount, abs=0.03)
    # alone, the beam leaves through the door at (5, 3) and ends on the far wall at x = 10
    assert alone[ahead] == pytest.approx(10.0 - 1.0 - mount, abs=0.03)


def test_a_robot_is_not_put_onto_another_between_two_sensor_steps() -> None:
    """Between sensor steps a drive meets only the robots it may touch; put by hand onto one
    further off, the robot is refused all the same, and beside it, it is put there."""
    fleet = Fleet(parse_map(room_map([])), 2, start=Pose2D(1.0, 3.0, 0.0))
    mover, other = fleet.simulators
    assert other.set_pose(Pose2D(8.0, 3.0, 0.0)) is None
    for _ in range(fleet.steps_per_sensor + 2):  # past a sensor step
        fleet.step()
    assert "would overlap another robot" in (mover.set_pose(Pose2D(8.2, 3.0, 0.0)) or "")
    assert mover.set_pose(Pose2D(7.0, 3.0, 0.0)) is None


def test_each_robot_hears_its_own_sensor_steps_and_one_that_stops_leaves_the_others_be() -> None:
    fleet = Fleet(parse_map(room_map([])), 2, start=Pose2D(1.0, 3.0, 0.0))
    loop = PacedLoop(fleet, speed=0)
    shares = robot_loops(loop)
    heard: list[list[Simulator]] = [[], []]
    for share, seen in zip(shares, heard, strict=True):
        share.on_sensor.append(seen.append)
    loop.start()
    try:
        wait_until(lambda: len(heard[0]) > 3 and len(heard[1]) > 3, 30, "sensor steps")
        assert {id(sim) for sim in heard[0]} == {id(fleet.simulators[0])}
        assert {id(sim) for sim in heard[1]} == {id(fleet.simulators[1])}
        assert shares[0].lock is shares[1].lock is loop.lock, "one lock for the fleet"
        shares[0].stop()  # its node went
        with loop.lock:
            stopped_at = len(heard[0])
            going_on = len(heard[1])
        wait_until(lambda: len(heard[1]) > going_on + 3, 30, "the other robot's steps")
        assert len(heard[0]) == stopped_at and not shares[0].running and shares[1].running
    finally:
        loop.stop()
    assert not shares[1].running and shares[1].error is None


@pytest.mark.heavy
def test_two_robots_swapping_places_never_overlap() -> None:
    fleet = Fleet(parse_map(room_map([])), 2, start=Pose2D(0.8, 3.0, 0.0))
    first, second = fleet.simulators
    assert second.set_pose(Pose2D(4.2, 3.0, math.pi)) is None
    assert first.go_to(Pose2D(4.2, 3.0)).found and second.go_to(Pose2D(0.8, 3.0)).found
    closest = math.inf
    while fleet.time < 120 and not (first.navigator.state.finished
                                    and second.navigator.state.finished):
        fleet.step()
        gap = polygon_gap(first.outline, second.outline)
        assert gap >= 0.0, f"overlapping by {-gap:.3f} m at {fleet.time:.2f} s"
        closest = min(closest, gap)
    assert closest < 1.0, "they met on the way"
    assert (first.navigator.state, second.navigator.state) == (robot.PathState.REACHED_GOAL,
                                                               robot.PathState.REACHED_GOAL)
    assert math.hypot(first.pose.x - 4.2, first.pose.y - 3.0) < 0.2
    assert math.hypot(second.pose.x - 0.8, second.pose.y - 3.0) < 0.2


def test_two_robots_meeting_head_on_in_a_doorway_settle_it_and_both_arrive() -> None:
    fleet = Fleet(parse_map(room_map([])), 2, start=Pose2D(2.5, 3.0, 0.0))
    first, second = fleet.simulators
    assert second.set_pose(Pose2D(7.5, 3.0, math.pi)) is None
    assert first.go_to(Pose2D(8.5, 3.0)).found and second.go_to(Pose2D(1.5, 3.0)).found
    states = set()
    while fleet.time < 120 and not (first.navigator.state.finished
                                    and second.navigator.state.finished):
        fleet.step()
        states.add(second.navigator.message)
        assert polygon_gap(first.outline, second.outline) >= 0.0
    assert fleet.way_giving.settled >= 1
    assert "making way for robot 1" in states, "the second in the fleet gave way"
    assert (first.navigator.state, second.navigator.state) == (robot.PathState.REACHED_GOAL,
                                                               robot.PathState.REACHED_GOAL)
    assert first.base.bumps == second.base.bumps == 0


def test_a_robot_in_the_doorway_backs_out_to_make_way_for_one_beyond_it() -> None:
    # the second stands in the door, the first just beyond it in a passage as narrow as the
    # door: the second makes way back in the room it came from (not past the first, on its
    # side), backing out of the door
    passage = [(5000, 2400, 8000, 2400), (5000, 3600, 8000, 3600)]
    fleet = Fleet(parse_map(room_map([], lines=passage)), 2, start=Pose2D(6.3, 3.0, math.pi))
    first, second = fleet.simulators
    assert second.set_pose(Pose2D(5.0, 3.0, 0.0)) is None
    assert first.go_to(Pose2D(1.5, 3.0)).found and second.go_to(Pose2D(8.5, 3.0)).found
    backed, beyond = False, False
    while fleet.time < 120 and not (first.navigator.state.finished
                                    and second.navigator.state.finished):
        fleet.step()
        backed |= second.navigator.making_way and second.base.speed < 0.0
        beyond |= second.navigator.making_way and second.pose.x > 5.6
        assert polygon_gap(first.outline, second.outline) >= 0.0
    assert fleet.way_giving.settled >= 1 and backed and not beyond
    assert (first.navigator.state, second.navigator.state) == (robot.PathState.REACHED_GOAL,
                                                               robot.PathState.REACHED_GOAL)
    assert first.base.bumps == second.base.bumps == 0


@pytest.mark.heavy
def test_a_fleet_on_the_bus_has_one_clock_and_a_namespace_and_frames_per_robot() -> None:
    with Context(BusConfig.isolated()) as context:
        spec = NodeSpec("simulator", "arnl", "/", {"map": str(CAMPUS), "robots": 3,
                                                   "speed": 5})
        running = component.start(context, spec)
        listener = Node("listener", "/test", context=context)
        scans: dict[str, LaserScan] = {}
        frames: dict[str, str] = {}

        def kept(message: TFMessage) -> None:
            frames.update({t.child_frame_id: t.header.frame_id for t in message.transforms})
        robot.TF_STATIC.subscription(listener, kept)
        namespaces = ["/robot1", "/robot2", "/robot3"]
        for namespace in namespaces:
            def scanned(message: LaserScan, namespace: str = namespace) -> None:
                scans[namespace] = message
            robot.SCAN.subscription(listener, scanned, namespace=namespace)
        try:
            assert "3 robots" in running.describe()
            wait_until(lambda: len(scans) == 3 and len(frames) == 3, 30, "three robots' scans")
            assert {n: scans[n].header.frame_id for n in namespaces} == {
                n: f"{n[1:]}/laser" for n in namespaces}
            assert frames == {f"{n[1:]}/laser": f"{n[1:]}/base_link" for n in namespaces}
            graph = context.graph
            wait_until(lambda: all(graph.count(f"{n}/pose", EntityKind.PUBLISHER)
                                   for n in namespaces), 10, "every robot's pose")
            assert graph.count("/clock", EntityKind.PUBLISHER) == 1, "one clock"
            assert graph.count(robot.INITIAL_POSE.name, EntityKind.SUBSCRIPTION) == 1
            assert [e.node_name for e in graph.endpoints(robot.INITIAL_POSE.name,
                                                         EntityKind.SUBSCRIPTION)] == [
                "/robot1/arnl"], "only the first robot follows /initialpose"
        finally:
            running.stop()
            listener.destroy()


@pytest.mark.parametrize("robots", [0, -1, 17, 2.5, True, "3"])
def test_a_bad_number_of_robots_is_refused_naming_the_parameter(robots: object) -> None:
    with Context(BusConfig.isolated()) as context:
        spec = NodeSpec("simulator", "arnl", "/", {"map": str(CAMPUS), "robots": robots},
                        where="fleet.toml: node 1 (arnl)")
        with pytest.raises(LaunchError, match=r"^fleet.toml: node 1 \(arnl\): parameter "
                                              r"`robots` must be a whole number from 1 to 16"):
            component.start(context, spec)
