"""Where the simulated people come from: the map's ``Sim.Person`` objects, or chosen at random.

**On the map.** A person is a point object of kind ``Sim.Person`` (as MobileSim's simulator
objects are ``Sim.*``, see ``Sim.BoxObstacle``): where they start, their name, and in the
description the waypoints they walk between, separated by ``;`` — goal names of the same map,
or ``x y`` in millimetres as the map's own coordinates::

    MapInfo: LocationType Name=Sim.Person "Label=Person" "Desc=Walks in the simulator"
    Cairn: Sim.Person 1200 -3400 0 "Lab; Hallway; 5000 2500" ICON "alice"

An empty description lets the person walk between goals of the map chosen at random, as
:func:`random_people` does. (The ``MapInfo`` line only lets map editors show the kind; the
simulator does not need it.) A waypoint that is not a goal and not two numbers, a person
standing inside a wall, or a description naming no waypoint is an error naming the map's line.

**At random.** :func:`random_people` places ``count`` people (the simulator's ``people``
parameter) at goals of the part of the map the robot can drive in, away from where the robots
start (one person a goal; more people than goals start on free points apart from the others),
each with a few other goals as waypoints (on free points when the map has fewer than
two goals a robot can reach). So every leg is between two goals, planned once for everybody
(:class:`~cyborg.sim.people_routes.RouteBook`). The same ``seed`` gives the same people.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from scipy import ndimage

from cyborg.nav.arnl_map import ArnlMap, MapError
from cyborg.nav.geometry import Pose2D
from cyborg.nav.map_objects import MapObject
from cyborg.nav.planner import Planner
from cyborg.sim.people_routes import Point
from cyborg.sim.person import PeopleSettings, PersonPlan

PERSON_KIND = "Sim.Person"
"""The map object kind of a simulated person."""
WAYPOINT_SEPARATOR = ";"
"""What separates a ``Sim.Person``'s waypoints in its description."""
KEEP_AWAY = 2.0
"""Metres a random person starts from every robot's start."""
APART = 1.0
"""Metres between the starts of two random people (but at distinct goals)."""
WAYPOINTS = (3, 5)
"""How many waypoints a random person gets, at least and at most."""


def people_on_map(arnl_map: ArnlMap, planner: Planner, seed: int = 0,
                  settings: PeopleSettings | None = None) -> list[PersonPlan]:
    """The map's ``Sim.Person`` objects as plans; MapError naming the line of a bad one."""
    settings = settings or PeopleSettings()
    random = np.random.default_rng(seed)
    plans: list[PersonPlan] = []
    for item in arnl_map.objects:
        if item.kind != PERSON_KIND or item.region is not None:
            continue
        where = f"{PERSON_KIND} {item.name!r}"
        clearance = planner.grid.clearance_at(planner.wall_clearance, item.x, item.y)
        if clearance < settings.radius:
            raise MapError(arnl_map.source, item.line,
                           f"{where} stands inside a wall or off the map at ({item.x:.2f}, "
                           f"{item.y:.2f}) ({clearance:.2f} m from the nearest wall; a person "
                           f"needs {settings.radius:g} m)")
        if item.description.strip():
            waypoints = tuple(_waypoint(arnl_map, item, text.strip(), where)
                              for text in item.description.split(WAYPOINT_SEPARATOR)
                              if text.strip())
            if not waypoints:
                raise MapError(arnl_map.source, item.line,
                               f"{where}: the description {item.description!r} names no "
                               f"waypoint (goal names or 'x y' in mm, separated by "
                               f"{WAYPOINT_SEPARATOR!r})")
        else:
            free = _free_points(planner, (item.x, item.y))
            waypoints = _random_waypoints(_reachable_goals(arnl_map, planner, free),
                                          (item.x, item.y), random, free)
        plans.append(PersonPlan(item.name or f"person {len(plans) + 1}", (item.x, item.y),
                                waypoints, item.line))
    return plans


def _waypoint(arnl_map: ArnlMap, item: MapObject, text: str, where: str) -> Point:
    parts = text.split()
    if len(parts) == 2:
        try:
            return float(parts[0]) / 1000.0, float(parts[1]) / 1000.0
        except ValueError:
            pass
    try:
        goal = arnl_map.goal(text)
    except KeyError as exc:
        reason = str(exc).strip("\"'")
        raise MapError(arnl_map.source, item.line,
                       f"{where}: waypoint {text!r} is neither a goal nor 'x y' in mm "
                       f"({reason})") from None
    return goal.x, goal.y


def random_people(arnl_map: ArnlMap, planner: Planner, count: int, seed: int = 0,
                  keep_away: Sequence[Point] = ()) -> list[PersonPlan]:
    """``count`` people on free points of ``arnl_map`` (see the module doc).

    ``keep_away`` are the robots' starts (m): nobody starts within :data:`KEEP_AWAY` of them,
    and everybody starts where the first can drive. ValueError for a negative count or a map
    with no room.
    """
    if count < 0:
        raise ValueError(f"people: a count of people is 0 or more, not {count}")
    if count == 0:
        return []
    random = np.random.default_rng(seed)
    free = _free_points(planner, keep_away[0] if keep_away else None)
    goals = _reachable_goals(arnl_map, planner, free)
    far_goals = [goal for goal in goals
                 if all(np.hypot(goal[0] - x, goal[1] - y) >= KEEP_AWAY for x, y in keep_away)]
    far = np.ones(len(free), bool)
    for x, y in keep_away:
        far &= np.hypot(free[:, 0] - x, free[:, 1] - y) >= KEEP_AWAY
    starts = free[far]
    if len(starts) == 0 and not far_goals:
        raise ValueError(f"people: {arnl_map.source} has no free point {KEEP_AWAY:g} m from "
                         "the robots for a person to start on")
    plans: list[PersonPlan] = []
    at_goals = [far_goals[index] for index in random.permutation(len(far_goals))] \
        if len(goals) >= 2 else []
    for number in range(count):
        if at_goals:  # at a goal: every leg is between goals, planned once for everybody
            start = at_goals.pop()
        else:  # at a free point, apart from the others
            taken = np.array([plan.start for plan in plans]).reshape(-1, 2)
            apart = np.ones(len(starts), bool)
            for x, y in taken:
                apart &= np.hypot(starts[:, 0] - x, starts[:, 1] - y) >= APART
            if not apart.any():
                raise ValueError(f"people: {arnl_map.source} has room for {len(plans)} "
                                 f"people ({APART:g} m apart, {KEEP_AWAY:g} m from the "
                                 f"robots), not {count}")
            x, y = starts[apart][random.integers(int(apart.sum()))]
            start = (float(x), float(y))
        plans.append(PersonPlan(f"person {number + 1}", start,
                                _random_waypoints(goals, start, random, free)))
    return plans


def _free_points(planner: Planner, near: Point | None) -> np.ndarray:
    """Centres of the cells a robot may stand on, in the region around ``near`` (if given)."""
    grid = planner.grid
    free = planner.clearance >= planner.lethal
    if near is not None:
        labels, _count = ndimage.label(free)
        rows, columns = np.nonzero(free)
        if len(rows):
            xs = grid.origin_x + (columns + 0.5) * grid.resolution
            ys = grid.origin_y + (rows + 0.5) * grid.resolution
            nearest = int(np.argmin(np.hypot(xs - near[0], ys - near[1])))
            free &= labels == labels[rows[nearest], columns[nearest]]
    rows, columns = np.nonzero(free)
    return np.column_stack([grid.origin_x + (columns + 0.5) * grid.resolution,
                            grid.origin_y + (rows + 0.5) * grid.resolution])


def _reachable_goals(arnl_map: ArnlMap, planner: Planner, free: np.ndarray) -> list[Point]:
    """The map's goals (not docks) a robot may stand on, in the region of ``free`` (cells)."""
    goals = []
    for item in arnl_map.goals():  # not the docks: nobody stands on the robots' charger
        if item.is_dock or planner.check(Pose2D(item.x, item.y)) is not None or len(free) == 0:
            continue
        if float(np.min(np.hypot(free[:, 0] - item.x, free[:, 1] - item.y))) <= 0.5:
            goals.append((item.x, item.y))
    return goals


def _random_waypoints(goals: list[Point], start: Point, random: np.random.Generator,
                      free: np.ndarray) -> tuple[Point, ...]:
    """A few of ``goals`` other than ``start``; points of ``free`` when there are too few."""
    count = int(random.integers(WAYPOINTS[0], WAYPOINTS[1] + 1))
    others = [goal for goal in goals if goal != start]
    if len(others) >= 2:
        order = random.permutation(len(others))[:count]
        return tuple(others[index] for index in order)
    if len(free) == 0:
        return (start,)
    picks = random.integers(len(free), size=count)
    return tuple((float(free[index, 0]), float(free[index, 1])) for index in picks)
