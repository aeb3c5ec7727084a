"""The bundled campus patrol with three robots and three people, without the bus: no jams.

A jam is a robot with a goal that moves less than :data:`MOVED` m for a while; the test drives
each robot round the bundled patrol's goals as its tree would (a failed goal tried again
twice, then the next one; a pause at each goal reached), feeds each navigator the people its
camera would see (as the tracker's objects reach it on the bus), and measures the longest jam
per robot in simulated time, as fast as the simulation runs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from importlib.resources import files
from pathlib import Path

from cyborg.nav.arnl_map import read_map
from cyborg.sim.crowd_geometry import line_clear
from cyborg.sim.fleet import Fleet
from cyborg.sim.navigator import PathState
from cyborg.sim.people_and_camera import Extras, make_crowd
from cyborg.sim.simulator import Simulator

CAMPUS = Path(str(files("cyborg.app").joinpath("data", "campus.map")))
PATROL = (("Lecture hall", 3.0), ("Library", 3.0), ("Courtyard", 2.0), ("Cafeteria", 3.0),
          ("Workshop", 2.0), ("Office", 2.0))
"""The bundled mission's patrol: goals and the seconds it waits at each."""
MOVED = 0.2
"""Metres a robot must move for a jam to end."""
SEEN = 8.0
"""Metres within which the camera's tracker reports a person in view (±55°, in sight)."""


@dataclass
class Patrolling:
    """One robot's round: where it goes, how often it tried, and its jam clock."""

    sim: Simulator
    goal: int = 0
    tries: int = 0
    driving: bool = False
    resume_at: float = 0.0
    anchor: tuple[float, float, float] = (0.0, 0.0, 0.0)  # where and when a jam began
    longest: float = 0.0


def patrol(fleet: Fleet, seconds: float) -> list[Patrolling]:
    """Run ``fleet`` round the patrol for ``seconds``; each robot's round and longest jam."""
    robots = [Patrolling(sim, anchor=(sim.pose.x, sim.pose.y, 0.0)) for sim in fleet.simulators]
    steps = 0
    while fleet.time < seconds:
        fleet.step()
        steps += 1
        if steps % fleet.steps_per_sensor:  # at the sensor rate, as the tree and the tracker
            continue
        for robot in robots:
            see_people(fleet, robot.sim)
            drive(robot, fleet.time)
    return robots


def see_people(fleet: Fleet, sim: Simulator) -> None:
    """The people the robot's camera sees, as the tracker's objects: discs to its navigator."""
    assert fleet.crowd is not None
    pose, grid = sim.pose, sim.planner.grid
    for index, person in enumerate(fleet.crowd.people):
        dx, dy = person.x - pose.x, person.y - pose.y
        if (0.3 < math.hypot(dx, dy) < SEEN
                and abs(math.remainder(math.atan2(dy, dx) - pose.theta, math.tau)) < 0.96
                and line_clear(sim.planner.wall_clearance, grid.origin_x, grid.origin_y,
                               grid.resolution, pose.x, pose.y, person.x, person.y, 0.01)):
            sim.navigator.obstacles.see(index, person.x, person.y, fleet.time)


def drive(robot: Patrolling, now: float) -> None:
    """The robot's tree, roughly: on to the next goal, tried three times, with pauses."""
    sim, state = robot.sim, robot.sim.navigator.state
    if robot.driving and state.finished:
        robot.driving = False
        if state is PathState.REACHED_GOAL or robot.tries >= 2:
            robot.resume_at = now + (PATROL[robot.goal][1] if robot.tries < 2 else 0.0)
            robot.goal, robot.tries = (robot.goal + 1) % len(PATROL), 0
        else:
            robot.tries += 1
    if not robot.driving and now >= robot.resume_at:
        robot.driving = sim.go_to(PATROL[robot.goal][0]).found
    x, y, since = robot.anchor
    if not robot.driving or math.hypot(sim.pose.x - x, sim.pose.y - y) >= MOVED:
        robot.anchor = (sim.pose.x, sim.pose.y, now)
    else:
        robot.longest = max(robot.longest, now - since)


def test_three_robots_and_three_people_on_the_campus_patrol_never_jam_for_a_minute() -> None:
    arnl_map = read_map(CAMPUS)
    fleet = Fleet(arnl_map, 3)
    starts = [(choice.pose.x, choice.pose.y) for choice in fleet.start_choices]
    fleet.crowd = make_crowd(arnl_map, fleet.simulators[0].planner,
                             Extras(3, 0, camera=False, image=False), starts)
    robots = patrol(fleet, 600.0)
    longest = [round(robot.longest) for robot in robots]
    assert max(longest) <= 60, f"longest jams per robot (s): {longest}"
    assert fleet.way_giving.settled >= 1, "the robots met head-on and settled it"
