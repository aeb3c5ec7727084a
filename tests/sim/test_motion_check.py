"""Commands are checked against the robot's momentum: a new goal given at full speed, a turn
where the body cannot turn, and hours of goals replaced at random never touch a wall; the path
follower slows down for sharp corners in time."""

from __future__ import annotations

import math
import random
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from cyborg.nav.arnl_map import parse_map, read_map
from cyborg.nav.geometry import Path as PlannedPath
from cyborg.nav.geometry import Pose2D, normalize_angle
from cyborg.sim.docking import DockState
from cyborg.sim.follower import PathFollower
from cyborg.sim.motion_check import (
    CREEP,
    MARGIN,
    Motion,
    Surroundings,
    safest_command,
    stopping_gap,
)
from cyborg.sim.navigator import PathState
from cyborg.sim.simulator import Simulator
from tests.small_maps import room_map

CORRIDOR = [(1000, 2675, 4000, 2675), (1000, 3325, 4000, 3325)]  # 0.65 m wide, along y = 3 m


def surroundings(sim: Simulator) -> Surroundings:
    grid = sim.planner.grid
    return Surroundings(sim.planner.wall_clearance, (grid.origin_x, grid.origin_y),
                        grid.resolution, sim.hits)


def moving(speed: float, turn_rate: float = 0.0) -> Motion:
    return Motion(speed, turn_rate, acceleration=0.5, turn_acceleration=1.74, step=0.02)


def test_the_gap_left_after_braking_is_the_wall_distance_less_the_stopping_distance() -> None:
    sim = Simulator(parse_map(room_map([])), start=Pose2D(3.0, 2.2, 0.0))
    footprint, around = sim.planner.footprint, surroundings(sim)
    # at 1 m/s braking at 0.5 m/s² takes 1 m; the body reaches 0.32 m ahead of the axle
    gap = stopping_gap(3.0, 2.2, 0.0, moving(1.0), (0.0, 0.0), 0.1, footprint, around)
    assert gap == pytest.approx(5.0 - (3.0 + 1.0 + 0.32), abs=0.06)
    assert stopping_gap(4.0, 2.2, 0.0, moving(1.0), (0.0, 0.0), 0.1, footprint, around) < 0
    # standing still, the gap is where the robot is; driving on for a period costs more room
    standing = stopping_gap(3.0, 2.2, 0.0, moving(0.0), (0.0, 0.0), 0.1, footprint, around)
    assert standing == pytest.approx(5.0 - 3.32, abs=0.06)
    assert stopping_gap(3.0, 2.2, 0.0, moving(1.0), (1.0, 0.0), 0.1, footprint, around) < gap


def test_a_turn_at_speed_beside_a_wall_is_softened_until_the_body_stays_clear() -> None:
    # driving east at 1 m/s and turning right at 1 rad/s, 0.6 m from the south wall: turning
    # harder would sweep the body into the wall before the robot stops
    sim = Simulator(parse_map(room_map([])), start=Pose2D(2.0, 0.6, 0.0))
    footprint, around = sim.planner.footprint, surroundings(sim)
    motion = moving(1.0, -1.0)
    wanted = (0.0, -1.5)
    assert stopping_gap(2.0, 0.6, 0.0, motion, wanted, 0.1, footprint, around) < 0
    chosen = safest_command(2.0, 0.6, 0.0, motion, wanted, 0.1, footprint, around)
    assert chosen != wanted
    assert stopping_gap(2.0, 0.6, 0.0, motion, chosen, 0.1, footprint, around) >= MARGIN
    # in open space the wanted command is kept
    assert safest_command(2.5, 3.0, 0.0, motion, wanted, 0.1, footprint, around) == wanted


def turn_towards(sim: Simulator, wanted: tuple[float, float], heading: float,
                 periods: int) -> list[tuple[float, float]]:
    """Ask again and again for ``wanted`` (checked) until the robot faces ``heading``; the
    commands given."""
    base, laser, footprint = sim.base, sim.laser, sim.planner.footprint
    given = []
    for _ in range(periods):
        pose = base.pose
        if abs(normalize_angle(pose.theta - heading)) < 0.1:
            break
        ranges = laser.scan(pose.x, pose.y, pose.theta)
        around = replace(surroundings(sim), hits=laser.points(pose.x, pose.y, pose.theta, ranges))
        command = safest_command(pose.x, pose.y, pose.theta,
                                 moving(base.speed, base.turn_rate), wanted, 0.1, footprint,
                                 around)
        given.append(command)
        for _ in range(5):
            base.command(*command, 0.02)
            assert base.body_clearance(base.pose) >= 0.0
    return given


def test_where_the_body_cannot_turn_the_robot_turns_as_far_as_it_can_and_stops() -> None:
    # the body (0.64 m long) cannot turn around in a 0.65 m corridor
    sim = Simulator(parse_map(room_map([], lines=CORRIDOR)), start=Pose2D(2.5, 3.0, 0.0))
    given = turn_towards(sim, (0.0, 1.5), math.pi, periods=300)
    assert given[-1] == (0.0, 0.0) and sim.base.turn_rate == 0.0
    assert 0.3 < sim.pose.theta < math.pi / 2  # turned some, short of across the corridor
    assert sim.base.bumps == 0


def test_where_the_body_cannot_turn_on_the_spot_it_backs_off_and_turns(shared: Path) -> None:
    # in room4 of AMROffice, close to the wall: turning right on the spot would swing the body
    # into it; backing off on a tight arc makes the room
    heading = 1.186
    sim = Simulator(read_map(shared / "maps" / "AMROffice.map"),
                    start=Pose2D(-7.055, 4.538, heading))
    given = turn_towards(sim, (0.0, -1.5), heading - math.pi / 2, periods=200)
    assert given[0] == (-CREEP, -1.5)  # backs off first
    assert abs(normalize_angle(sim.pose.theta - (heading - math.pi / 2))) < 0.1  # then turns
    assert sim.base.bumps == 0


def test_the_follower_slows_down_in_time_for_a_sharp_corner() -> None:
    straight = PathFollower(PlannedPath([(0.0, 0.0), (5.0, 0.0), (10.0, 0.0)]), False)
    corner = PathFollower(PlannedPath([(0.0, 0.0), (5.0, 0.0), (5.0, 5.0)]), False)
    gentle = PathFollower(PlannedPath([(0.0, 0.0), (5.0, 0.0), (10.0, 1.0)]), False)
    far, near = Pose2D(1.0, 0.0), Pose2D(4.0, 0.0)  # 4 m and 1 m before the corner

    def speed(follower: PathFollower, pose: Pose2D) -> float:
        return follower.update(pose, math.inf).speed

    assert speed(straight, far) == speed(straight, near) == pytest.approx(1.0)
    assert speed(gentle, near) == pytest.approx(1.0)  # an 11° bend is no corner
    assert speed(corner, far) == pytest.approx(1.0)  # 4 m is room enough to brake
    # 1 m before a right angle: only as fast as braking at 0.5 m/s² reaches 0.25 m/s by the
    # point the carrot (0.5 m ahead) turns the corner
    assert speed(corner, near) == pytest.approx(math.sqrt(0.25 ** 2 + 2 * 0.5 * 0.5), abs=1e-6)


def test_a_goal_replaced_at_full_speed_is_reached_without_touching_a_wall(shared: Path) -> None:
    # heading south at 1 m/s beside a slanted wall when the new goal (room1) lies behind: turning
    # on the spot at once would swing the body into the wall while the robot still rolls
    sim = Simulator(read_map(shared / "maps" / "AMROffice.map"),
                    start=Pose2D(1.373, -0.904, math.radians(-88.4)))
    sim.base.speed = 1.0
    assert sim.go_to("room1").found
    assert sim.run_until(lambda: sim.navigator.state.finished, timeout=120)
    assert sim.navigator.state is PathState.REACHED_GOAL, sim.navigator.message
    assert sim.base.bumps == 0


@pytest.mark.heavy
def test_hours_of_goals_replaced_at_random_moments_touch_no_wall(shared: Path) -> None:
    """The patrol of the mission, but each move may be abandoned at any moment for the next goal
    or the dock: the robot never touches a wall and nearly every move arrives."""
    rng = random.Random(5)
    sim = Simulator(read_map(shared / "maps" / "AMROffice.map"), start="Dock")
    patrol = ["room1", "room2", "Outside", "room4"]
    arrived = failed = 0
    for round_ in range(160):
        sim.go_to(patrol[round_ % len(patrol)])
        cut = rng.random() < 0.3
        sim.run_until(lambda: finished(sim), rng.uniform(1.0, 60.0) if cut else 600.0)
        arrived += sim.navigator.state is PathState.REACHED_GOAL
        failed += sim.navigator.state is PathState.FAILED_MOVE
        if cut and rng.random() < 0.5:
            sim.cancel()
            assert sim.dock(), sim.docking.message
            sim.run_until(lambda: sim.docking.state is not DockState.DOCKING, 600.0)
        else:
            sim.run(rng.uniform(0.0, 3.0))
    assert sim.base.bumps == 0
    assert arrived >= 100 and failed <= 2, (arrived, failed)


def finished(sim: Simulator) -> bool:
    return sim.navigator.state.finished and sim.docking.state is DockState.UNDOCKED


def test_a_robot_wedged_beside_another_creeps_out_rather_than_stand_for_good() -> None:
    # another robot's outline (kept 10 cm clear of) runs along the robot's left side, 7 cm
    # inside that margin; the follower wants forwards and round to the right, which swings the
    # back a hair closer: it used to brake, every period, for good
    sim = Simulator(parse_map(room_map([])), start=Pose2D(2.5, 1.5, 0.0))
    grid = sim.planner.grid
    beside = [(1.0 + 0.02 * k, 1.5 + 0.17) for k in range(80)]  # a line of points, y = 1.67
    around = Surroundings(sim.planner.wall_clearance, (grid.origin_x, grid.origin_y),
                          grid.resolution, np.array(beside))
    wanted = (0.6, -1.5)
    assert stopping_gap(2.5, 1.5, 0.0, moving(0.0), wanted, 0.1, sim.planner.footprint,
                        around) < stopping_gap(2.5, 1.5, 0.0, moving(0.0), (0.0, 0.0), 0.1,
                                               sim.planner.footprint, around) < MARGIN
    command = safest_command(2.5, 1.5, 0.0, moving(0.0), wanted, 0.1, sim.planner.footprint,
                             around)
    assert abs(command[0]) == CREEP and command[1] == 0.0, command
