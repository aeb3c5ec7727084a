"""The navigator with objects seen lately: around a person where there is room, waiting where
there is none, on again once the person is forgotten; waiting is not stalling."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from cyborg.nav.arnl_map import parse_map, read_map
from cyborg.nav.geometry import Pose2D
from cyborg.sim.navigator import NavigatorSettings, PathState
from cyborg.sim.simulator import SimSettings, Simulator
from tests.small_maps import corridor_map

SEEN_EVERY = 0.1  # seconds between the tracker's lists, as at 10 frames a second


@dataclass
class Person:
    """A person the tracker reports standing at ``(x, y)`` from ``appears`` until ``leaves``."""

    x: float
    y: float
    appears_at_x: float  # the person is first seen when the robot gets this far
    stays: float = math.inf  # seconds seen after first seen
    seen_from: float | None = None
    closest: float = math.inf
    states: list[PathState] = field(default_factory=list)

    def report(self, sim: Simulator) -> None:
        if self.seen_from is None and sim.pose.x >= self.appears_at_x:
            self.seen_from = sim.time
        if self.seen_from is not None and sim.time - self.seen_from <= self.stays:
            sim.navigator.obstacles.see(1, self.x, self.y, seen_at=sim.time)
            self.closest = min(self.closest, math.hypot(sim.pose.x - self.x,
                                                        sim.pose.y - self.y))


def drive(sim: Simulator, person: Person, timeout: float) -> None:
    """Run until the goal is over, the tracker reporting ``person`` every ``SEEN_EVERY`` s."""
    end, reported = sim.time + timeout, -math.inf
    while not sim.navigator.state.finished and sim.time < end:
        if sim.time - reported >= SEEN_EVERY:
            reported = sim.time
            person.report(sim)
        sim.step()
        if not person.states or person.states[-1] is not sim.navigator.state:
            person.states.append(sim.navigator.state)


def corridor(width: float, settings: NavigatorSettings | None = None) -> Simulator:
    return Simulator(parse_map(corridor_map(width)), start=Pose2D(1.0, width / 2, 0.0),
                     settings=SimSettings(navigator=settings or NavigatorSettings()))


def test_a_person_in_a_wide_corridor_is_driven_around() -> None:
    sim = corridor(3.6)
    assert sim.go_to(Pose2D(13.0, 1.8)).found
    person = Person(7.0, 1.8, appears_at_x=2.5)
    drive(sim, person, timeout=120)
    assert sim.navigator.state is PathState.REACHED_GOAL, sim.navigator.message
    assert sim.navigator.replans >= 1 and sim.navigator.waits == 0
    assert PathState.WAITING_FOR_PATH not in person.states
    assert person.closest >= 0.7, "the robot kept the person's clearance"
    assert sim.base.bumps == 0


def test_a_person_in_a_narrow_corridor_is_waited_for_longer_than_the_stall_timeout() -> None:
    sim = corridor(2.0)
    assert sim.go_to(Pose2D(13.0, 1.0)).found
    stall = sim.navigator.settings.stall_timeout
    person = Person(7.0, 1.0, appears_at_x=2.5, stays=stall + 10.0)
    drive(sim, person, timeout=stall + 5.0)
    assert sim.navigator.state is PathState.WAITING_FOR_PATH, sim.navigator.message
    assert "block every way" in sim.navigator.message
    assert abs(sim.base.speed) < 0.01, "the robot stands while it waits"
    waited_at = sim.pose.x
    assert waited_at < 7.0 - 0.8, "it stopped short of the person"
    drive(sim, person, timeout=120)
    assert person.states == [PathState.MOVING_TO_GOAL, PathState.WAITING_FOR_PATH,
                             PathState.MOVING_TO_GOAL, PathState.REACHED_GOAL]
    assert sim.navigator.waits == 1 and sim.base.bumps == 0
    assert person.seen_from is not None
    forget_after = sim.navigator.obstacles.settings.forget_after
    assert sim.time > person.seen_from + person.stays + forget_after


def test_a_wait_that_never_ends_gives_up_after_the_wait_timeout() -> None:
    sim = corridor(2.0, NavigatorSettings(wait_timeout=8.0))
    assert sim.go_to(Pose2D(13.0, 1.0)).found
    person = Person(7.0, 1.0, appears_at_x=2.5)
    drive(sim, person, timeout=120)
    assert sim.navigator.state is PathState.FAILED_MOVE
    assert "waited 8 s" in sim.navigator.message
    assert person.seen_from is not None and sim.time < person.seen_from + 15.0


def test_a_goal_given_while_a_person_blocks_the_only_way_starts_out_waiting() -> None:
    sim = corridor(2.0)
    sim.navigator.obstacles.see(1, 5.0, 1.0, seen_at=sim.time)
    plan = sim.go_to(Pose2D(13.0, 1.0))
    assert plan.found, "the goal itself is reachable"
    assert sim.navigator.waiting and sim.navigator.follower is None
    sim.run(10.0)  # the person is not seen again: forgotten after 4 s, the way is open
    assert not sim.navigator.waiting and sim.navigator.follower is not None
    assert sim.run_until(lambda: sim.navigator.state.finished, timeout=60)
    assert sim.navigator.state is PathState.REACHED_GOAL


def test_cancelling_a_wait_ends_the_goal() -> None:
    sim = corridor(2.0)
    sim.navigator.obstacles.see(1, 5.0, 1.0, seen_at=sim.time)
    sim.go_to(Pose2D(13.0, 1.0))
    sim.cancel()
    assert sim.navigator.state is PathState.ABORTED_PATHPLAN


def laser_sees_for(sim: Simulator, where: tuple[float, float], seconds: float) -> int:
    """Someone the laser sees at ``where`` for ``seconds``, then gone; the replans meanwhile."""
    sim.meet((), people=np.array([[where[0], where[1], 0.25]]))
    sim.run(seconds)
    sim.meet((), people=np.zeros((0, 3)))
    return sim.navigator.replans


def test_someone_crossing_the_path_briefly_is_not_planned_around() -> None:
    sim = corridor(3.6)
    assert sim.go_to(Pose2D(13.0, 1.8)).found
    sim.run(1.0)
    assert laser_sees_for(sim, (sim.pose.x + 2.0, 1.8), 0.5) == 0
    sim.run_until(lambda: sim.navigator.state.finished, timeout=60)
    assert sim.navigator.state is PathState.REACHED_GOAL and sim.navigator.replans == 0


def test_someone_who_stays_on_the_path_is_planned_around() -> None:
    sim = corridor(3.6)
    assert sim.go_to(Pose2D(13.0, 1.8)).found
    sim.run(1.0)
    settings = sim.navigator.settings
    stays = settings.blocked_persistence + settings.replan_interval + 0.5
    assert laser_sees_for(sim, (sim.pose.x + 2.0, 1.8), stays) >= 1


def test_a_wait_ends_where_the_laser_sees_only_the_maps_walls(shared: Path) -> None:
    # AMROffice's passages are hardly wider than the robot: its walls, seen again as laser
    # returns a cell off the map's, closed every plan past what the laser sees, so a wait for
    # a person never ended there, though the person had long gone (a minute, then FAILED_MOVE)
    sim = Simulator(read_map(shared / "maps" / "AMROffice.map"), "room2")
    assert sim.go_to("room1").found
    while sim.time < 3.0:  # someone in the corridor ahead, for a while; then gone
        sim.navigator.obstacles.see(1, -7.45, -1.2, sim.time)
        sim.step()
    states = [sim.navigator.state]
    while not sim.navigator.state.finished and sim.time < 60.0:
        sim.step()
        if sim.navigator.state is not states[-1]:
            states.append(sim.navigator.state)
    assert sim.navigator.state is PathState.REACHED_GOAL, (states, sim.navigator.message)


def test_a_robot_nosed_against_a_wall_corner_drives_on_round_it(shared: Path) -> None:
    # AMROffice: a robot that had stopped for a person at a corridor's end faces the corner of
    # the wall beside it, its path turning away round it: the corner, in the corridor ahead as
    # wide as the robot, stopped the follower at every plan (two minutes of FAILED_MOVE); the
    # map's walls are the path's and the motion check's to keep clear of, not a stop
    sim = Simulator(read_map(shared / "maps" / "AMROffice.map"), Pose2D(-6.878, -0.225, 0.70))
    assert sim.go_to("Outside").found
    sim.run(15.0)
    assert sim.navigator.state is PathState.MOVING_TO_GOAL, sim.navigator.message
    assert math.hypot(sim.pose.x + 6.878, sim.pose.y + 0.225) > 2.0, "on its way"
    assert sim.base.bumps == 0
