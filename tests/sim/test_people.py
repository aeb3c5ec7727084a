"""People walking in the simulator: their speeds and pauses, walls and robots kept clear of,
the map's Sim.Person objects and their errors, and the laser seeing them."""

from __future__ import annotations

import math
from functools import cache
from importlib.resources import files
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cyborg.nav.arnl_map import ArnlMap, MapError, parse_map, read_map
from cyborg.nav.footprint import PIONEER_LX
from cyborg.nav.geometry import Pose2D
from cyborg.nav.planner import Planner
from cyborg.sim.bodies import outline_at
from cyborg.sim.people import Crowd
from cyborg.sim.people_sources import people_on_map, random_people
from cyborg.sim.person import Gait, PeopleSettings, Person, PersonPlan
from cyborg.sim.simulator import Simulator
from tests.small_maps import room_map

CAMPUS = Path(str(files("cyborg.app").joinpath("data", "campus.map")))
GOALS = ['Goal 2000 1500 0 "" ICON "west"', 'Goal 2000 4500 0 "" ICON "north"',
         'Goal 8000 3000 0 "" ICON "east"']


@cache
def campus() -> tuple[ArnlMap, Planner]:
    arnl_map = read_map(CAMPUS)
    return arnl_map, Planner(arnl_map)


def room(*cairns: str) -> tuple[ArnlMap, Planner]:
    arnl_map = parse_map(room_map([*GOALS, *cairns]), "room.map")
    return arnl_map, Planner(arnl_map)


def robot_at(pose: Pose2D) -> np.ndarray:
    """A Pioneer LX's outline standing at ``pose`` in the room."""
    return outline_at(PIONEER_LX.polygon(), pose)


def beside_a_robot(plan: PersonPlan, pose: Pose2D) -> tuple[Planner, Crowd, Person, np.ndarray]:
    """One person walking ``plan`` in the room, and a robot's outline standing at ``pose``."""
    _map, planner = room()
    crowd = Crowd(planner, [plan], seed=1)
    return planner, crowd, crowd.people[0], robot_at(pose)


def test_a_person_walks_at_their_own_speed_and_pauses_at_each_waypoint() -> None:
    _map, planner = room()
    plan = PersonPlan("ann", (2.0, 1.5), ((2.0, 4.5), (2.0, 1.5)))
    crowd = Crowd(planner, [plan], seed=4)
    person, s = crowd.people[0], crowd.settings
    assert s.min_speed <= person.speed <= s.max_speed
    steps: list[float] = []
    pauses: list[float] = []
    paused_at: float | None = None
    for _ in range(600):
        before = (person.x, person.y, person.gait)
        crowd.advance(0.1)
        if before[2] is Gait.WALKING and person.gait is Gait.WALKING:
            steps.append(math.hypot(person.x - before[0], person.y - before[1]))
        if person.gait is Gait.PAUSING and paused_at is None:
            paused_at = crowd.time
            assert min(math.dist((person.x, person.y), point) for point in plan.waypoints) < 0.01
        if person.gait is not Gait.PAUSING and paused_at is not None:
            pauses.append(crowd.time - paused_at)
            paused_at = None
    assert np.median(steps) == pytest.approx(person.speed * 0.1, rel=1e-6)
    assert max(steps) <= person.speed * 0.1 + 1e-9
    assert len(pauses) >= 3, "to and fro, pausing at both ends"
    assert all(s.min_pause - 0.11 <= pause <= s.max_pause + 0.11 for pause in pauses)
    assert len({round(pause, 1) for pause in pauses}) > 1, "pauses of random length"


def test_speeds_are_drawn_per_person_within_human_range() -> None:
    arnl_map, planner = campus()
    crowd = Crowd(planner, random_people(arnl_map, planner, 12, seed=2, keep_away=[(2.0, 1.2)]),
                  seed=2)
    speeds = [person.speed for person in crowd.people]
    assert all(0.5 <= speed <= 1.5 for speed in speeds)
    assert max(speeds) - min(speeds) > 0.3


@settings(max_examples=6, deadline=None)
@given(seed=st.integers(0, 10_000))
def test_people_never_walk_into_walls_or_each_other(seed: int) -> None:
    arnl_map, planner = campus()
    plans = random_people(arnl_map, planner, 5, seed=seed, keep_away=[(2.0, 1.2)])
    crowd = Crowd(planner, plans, seed=seed)
    radius = crowd.settings.radius
    for _ in range(400):
        crowd.advance(0.1)
        for x, y in crowd.positions:
            assert planner.grid.clearance_at(planner.wall_clearance, x, y) >= radius
        gaps = np.hypot(*(crowd.positions[:, None, :] - crowd.positions[None, :, :]).T)
        np.fill_diagonal(gaps, np.inf)
        assert gaps.min() >= 2 * radius - 1e-9, "bodies never overlap"


def test_the_same_seed_gives_the_same_people_and_walks() -> None:
    arnl_map, planner = campus()
    walks = []
    for _ in range(2):
        crowd = Crowd(planner, random_people(arnl_map, planner, 4, seed=9), seed=9)
        for _ in range(200):
            crowd.advance(0.1)
        walks.append(crowd.positions)
    assert np.array_equal(walks[0], walks[1])


def test_a_person_stops_for_the_robot_and_turns_back_when_it_stays() -> None:
    _map, planner = room()
    crowd = Crowd(planner, [PersonPlan("bo", (2.0, 1.5), ((2.0, 4.5),))], seed=1)
    person = crowd.people[0]
    robot = robot_at(Pose2D(2.0, 3.2, math.pi / 2))
    closest, states = math.inf, []
    for _ in range(100):
        crowd.advance(0.1, [robot])
        closest = min(closest, math.hypot(person.x - 2.0, person.y - 3.2))
        states.append(person.gait)
    assert Gait.WAITING in states
    assert closest >= crowd.settings.radius + 0.3, "never touches the robot"
    waited = states.index(Gait.WAITING)
    assert Gait.WALKING in states[waited:], "gave up waiting"
    assert person.y < 2.5, "walked back the way they came"


def test_the_maps_people_walk_their_named_and_numbered_waypoints() -> None:
    arnl_map, planner = room('Sim.Person 3000 3000 0 "north; 8000 1000; west" ICON "cy"',
                             'Sim.Person 7000 3000 0 "" ICON ""')
    plans = people_on_map(arnl_map, planner, seed=1)
    assert [plan.name for plan in plans] == ["cy", "person 2"]
    assert plans[0].start == (3.0, 3.0)
    assert plans[0].waypoints == ((2.0, 4.5), (8.0, 1.0), (2.0, 1.5))
    assert set(plans[1].waypoints) <= {(2.0, 1.5), (2.0, 4.5), (8.0, 3.0)}, "goals at random"


@pytest.mark.parametrize(("cairn", "said"), [
    ('Sim.Person 3000 3000 0 "north; library" ICON "cy"',
     r"room\.map:6: Sim\.Person 'cy': waypoint 'library' is neither a goal nor 'x y' in mm"),
    ('Sim.Person 5000 1000 0 "north" ICON "cy"',
     r"room\.map:6: Sim\.Person 'cy' stands inside a wall"),
    ('Sim.Person 3000 3000 0 " ; " ICON "cy"',
     r"room\.map:6: Sim\.Person 'cy': the description ' ; ' names no waypoint"),
])
def test_a_bad_person_on_the_map_is_an_error_naming_the_line(cairn: str, said: str) -> None:
    arnl_map, planner = room(cairn)
    with pytest.raises(MapError, match=said):
        people_on_map(arnl_map, planner)


def test_random_people_start_away_from_the_robots_and_never_on_the_dock() -> None:
    arnl_map, planner = campus()
    dock = arnl_map.docks()[0]
    plans = random_people(arnl_map, planner, 20, seed=5, keep_away=[(dock.x, dock.y)])
    assert all(math.dist(plan.start, (dock.x, dock.y)) >= 2.0 for plan in plans)
    assert all((dock.x, dock.y) not in plan.waypoints for plan in plans)
    with pytest.raises(ValueError, match="people: a count of people is 0 or more, not -1"):
        random_people(arnl_map, planner, -1)


def test_the_laser_sees_a_person_in_front_of_the_robot() -> None:
    arnl_map = parse_map(room_map(GOALS), "room.map")
    sim = Simulator(arnl_map, Pose2D(1.5, 3.0, 0.0))
    ahead = sim.laser.spec.beams // 2
    empty = float(sim.ranges[ahead])
    sim.crowd = Crowd(sim.planner, [PersonPlan("still", (4.3, 3.0), ((4.3, 3.0),))],
                      settings=PeopleSettings(radius=0.3))
    sim.run(0.5)
    expected = 4.3 - 0.3 - (1.5 + sim.laser.spec.mount_x)
    assert empty > 3.0, "the wall is further"
    assert float(sim.ranges[ahead]) == pytest.approx(expected, abs=0.03)
    assert sim.others, "near: a body the drive cannot enter"


def test_a_person_steps_out_of_the_way_of_a_robot_coming_at_them() -> None:
    pose = Pose2D(2.0, 3.2, math.pi / 2)
    planner, crowd, person, robot = beside_a_robot(
        PersonPlan("cy", (2.0, 4.2), ((2.0, 4.2),)), pose)
    for _ in range(20):
        crowd.advance(0.1, [robot], [pose.theta])
    assert abs(person.x - 2.0) >= 0.4 + crowd.settings.radius, "aside, out of its way"
    assert planner.grid.clearance_at(planner.wall_clearance, person.x, person.y) >= 0.25


def test_nobody_pauses_in_a_doorway_but_in_the_rooms() -> None:
    _map, planner = room()
    door, west = (5.0, 3.0), (2.0, 3.0)  # the wall's 1.2 m door, too narrow to pass anyone
    crowd = Crowd(planner, [PersonPlan("di", west, (door, west))], seed=2)
    person = crowd.people[0]
    assert crowd.narrow(*door) and not crowd.narrow(*west)
    pauses: dict[tuple[float, float], list[float]] = {door: [], west: []}
    for _ in range(400):
        crowd.advance(0.1)
        if person.gait is Gait.PAUSING:
            stints = pauses[person.goal]
            stints.append(crowd.time - person.until)  # negative while the pause lasts
    assert min(pauses[west]) <= -crowd.settings.min_pause + 0.2, "they pause in the room"
    assert pauses[door] and max(-t for t in pauses[door]) <= 0.0, "not in the door"


def test_a_person_walking_past_a_robot_that_stands_walks_on() -> None:
    # the robot stands facing north at the room's middle; the person walks west to east
    # across the line ahead of it, where a robot driving at them would have them step aside
    pose = Pose2D(2.5, 3.2, math.pi / 2)
    _planner, crowd, person, robot = beside_a_robot(
        PersonPlan("ed", (1.0, 4.2), ((4.0, 4.2),)), pose)
    for _ in range(60):
        crowd.advance(0.1, [robot], [pose.theta], [0.0])
    assert person.x > 3.5, "they crossed in front of it instead of standing beside its way"


def test_a_person_on_the_way_a_robot_waits_to_drive_steps_off_it() -> None:
    pose = Pose2D(3.0, 3.0, 0.0)  # west of the door, waiting to drive east through it
    planner, crowd, person, robot = beside_a_robot(
        PersonPlan("fay", (7.0, 3.0), ((7.0, 3.0),)), pose)
    way = np.column_stack([np.arange(3.0, 9.0, 0.2), np.full(30, 3.0)])
    for _ in range(100):
        crowd.advance(0.1, [robot], [pose.theta], [0.0], [way])
    gap = float(np.min(np.hypot(way[:, 0] - person.x, way[:, 1] - person.y)))
    assert gap >= planner.lethal + crowd.settings.radius, "off the way the robot waits to take"


def test_a_person_squeezed_against_a_wall_can_still_step_out_of_a_robots_way() -> None:
    pose = Pose2D(1.15, 3.0, math.pi)  # a robot right in front of them, facing the wall
    _planner, crowd, person, robot = beside_a_robot(
        PersonPlan("gus", (0.27, 3.0), ((0.27, 3.0),)), pose)  # 2 cm closer than they keep
    for _ in range(20):
        crowd.advance(0.1, [robot], [pose.theta])
    assert abs(person.y - 3.0) > 0.3, "along the wall, out of its way"
    assert person.x >= 0.27 - 1e-6, "no closer to the wall than they were"


def test_a_person_in_a_niche_beside_a_waiting_robots_way_goes_on_along_it(
        shared: Path) -> None:
    # AMROffice: a robot at the junction waits to drive up the corridor north and on east; a
    # person in the niche where the corridor turns, a step off its way, has no room aside
    # and used to step into the niche and back onto their way for good
    arnl_map = read_map(shared / "maps" / "AMROffice.map")
    sim = Simulator(arnl_map, Pose2D(-5.9, 1.07, 2.33))
    assert sim.go_to("Outside").found
    way, pose = sim.way_ahead(), sim.pose
    crowd = Crowd(sim.planner, [PersonPlan("hal", (-6.14, 5.29), ((2.471, -2.473),))], seed=1)
    person = crowd.people[0]
    person.route = np.array([(-6.21, 5.49), (-7.21, 5.44), (-7.41, 1.74)])  # down the corridor
    for _ in range(150):
        crowd.advance(0.2, [sim.outline], [pose.theta], [0.0], [way])
    gap = float(np.min(np.hypot(way[:, 0] - person.x, way[:, 1] - person.y)))
    assert gap >= sim.planner.lethal + crowd.settings.radius, (person.x, person.y, gap)


def test_a_person_on_a_waiting_robots_way_with_no_room_aside_walks_straight_off_it(
        shared: Path) -> None:
    # AMROffice: a robot west of the junction waits to drive east round it and south to room2;
    # a person at the junction's inner corner, on that way, has a wall where a step aside
    # would go: stepping aside and on along the way in turns, they stayed on it for seconds
    # (once for a minute); now they walk to the nearest place off it and stay there
    arnl_map = read_map(shared / "maps" / "AMROffice.map")
    sim = Simulator(arnl_map, Pose2D(-8.39, 2.03, -0.467))
    assert sim.go_to("room2").found
    way, pose = sim.way_ahead(), sim.pose
    crowd = Crowd(sim.planner, [PersonPlan("ivy", (-5.37, 1.38), ((-5.157, 8.727),))], seed=1)
    person = crowd.people[0]
    room = sim.planner.lethal + crowd.settings.radius + 0.3  # what a person keeps from a way
    on_the_way = []
    for _ in range(50):
        crowd.advance(0.2, [sim.outline], [pose.theta], [0.0], [way])
        gap = float(np.min(np.hypot(way[:, 0] - person.x, way[:, 1] - person.y)))
        on_the_way.append(gap < room)
    assert not any(on_the_way[5:]), f"off the way within a second, for good: {on_the_way}"
    assert sim.planner.grid.clearance_at(sim.planner.wall_clearance, person.x,
                                         person.y) >= crowd.settings.radius


def test_a_person_turning_a_corner_does_not_walk_into_someone_round_it() -> None:
    # one walks north to a corner of their route and then east; another stands east of the
    # corner, out of the way north: the walker stops at the corner rather than turn into them
    # in mid-step (what is ahead was looked at facing north)
    _map, planner = room()
    crowd = Crowd(planner, [PersonPlan("jo", (2.0, 2.0), ((2.0, 2.0),)),
                            PersonPlan("kim", (2.65, 2.98), ((2.65, 2.98),))], seed=1)
    walker, standing = crowd.people
    walker.gait, walker.route = Gait.WALKING, np.array([(2.0, 2.96), (4.0, 3.0)])
    walker.speed = 1.5
    standing.gait = Gait.STANDING
    for _ in range(10):
        crowd.advance(0.2)
        gap = math.hypot(walker.x - standing.x, walker.y - standing.y)
        assert gap >= 2 * crowd.settings.radius - 1e-9, (walker.x, walker.y)
