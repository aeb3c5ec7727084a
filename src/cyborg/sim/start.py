"""Where the simulated robot starts, and the sentence that says why.

The first that applies wins:

1. the pose, or the goal or dock named, that the caller gives (``--start``);
2. the map's home: a ``RobotHome`` point (as ARNL localises at start-up);
3. a ``RobotHome`` area: its free point nearest the area's middle;
4. the map's first dock (a robot at rest is usually on its charger);
5. the free point nearest the centre of the map's extent.

Goals are *not* start places: a map may hold goals that no robot can stand on (columbia.map
has one inside a forbidden area and one inside a wall). For 3 and 5 "free" means clear of walls
and forbidden zones by the planner's lethal distance (the robot's circumscribed radius plus
padding) and :data:`START_MARGIN` more, on the planner's own clearance grid: the robot can turn
on the spot there, and every plan can leave from it. The map's centre on its own can be a wall,
a pillar or the open air outside an L-shaped building (see
:meth:`cyborg.nav.grid.MapGrid.nearest_clear`).

The choice comes with a ``reason``, which the simulator logs: a start the map names is
information, a start the simulator had to invent is a warning that the map lacks a home.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from cyborg.nav.arnl_map import ArnlMap
from cyborg.nav.geometry import Pose2D
from cyborg.nav.map_objects import MapObject
from cyborg.nav.planner import Planner

START_MARGIN = 0.1  # metres of clearance beyond the planner's lethal distance


@dataclass(frozen=True)
class StartChoice:
    """The start pose and why (a sentence naming the map, the rule and the pose)."""

    pose: Pose2D
    reason: str
    invented: bool = False  # the map names no start: a home or dock would be better


def choose_start(arnl_map: ArnlMap, planner: Planner,
                 start: Pose2D | str | None = None) -> StartChoice:
    """Where to put the robot on ``arnl_map``; see the module docstring for the rules.

    ``start`` is a pose, or the name of a home point, goal or dock (KeyError listing the
    goals if the map has none of that name).
    """
    source = arnl_map.source
    if isinstance(start, Pose2D):
        return StartChoice(start, f"{source}: starting at the given pose {_where(start)}")
    if start is not None:
        named_homes = [home for home in arnl_map.homes()
                       if home.name == start and home.region is None]
        item = named_homes[0] if named_homes else arnl_map.goal(start)
        pose = Pose2D(item.x, item.y, item.theta)
        return StartChoice(pose, f"{source}: starting at {item.kind} {item.name!r} "
                                 f"{_where(pose)}")
    homes = arnl_map.homes()
    for item in homes:
        if item.region is None:
            pose = Pose2D(item.x, item.y, item.theta)
            return StartChoice(pose, f"{source}: starting at the map's home {_where(pose)}")
    needed = planner.lethal + START_MARGIN
    for item in homes:
        in_area = _free_in_area(planner, item, needed)
        if in_area is not None:
            return StartChoice(in_area, f"{source}: starting in the map's home area (line "
                                        f"{item.line}) at its free point nearest its middle "
                                        f"{_where(in_area)}")
    for item in arnl_map.docks():
        pose = Pose2D(item.x, item.y, item.theta)
        return StartChoice(pose, f"{source}: starting at dock {item.name!r} {_where(pose)}")
    return _near_centre(arnl_map, planner, needed)


def _near_centre(arnl_map: ArnlMap, planner: Planner, needed: float) -> StartChoice:
    min_x, min_y, max_x, max_y = arnl_map.bounds()
    centre_x, centre_y = (min_x + max_x) / 2, (min_y + max_y) / 2
    grid, clearance = planner.grid, planner.clearance
    found = grid.nearest_clear(clearance, centre_x, centre_y, needed)
    lacking = f"{arnl_map.source} has no home or dock"
    if found is not None:
        pose = Pose2D(found.x, found.y)
        outside = "" if found.enclosed else (" (outside the map's walls: no point inside them "
                                             "is that clear)")
        return StartChoice(pose, f"{lacking}; starting at the free point nearest the centre "
                                 f"({centre_x:.2f}, {centre_y:.2f}) of the map: {_where(pose)}, "
                                 f"{needed:.2f} m or more from walls and forbidden zones"
                                 f"{outside}", invented=True)
    row, column = np.unravel_index(int(np.argmax(clearance)), clearance.shape)
    pose = Pose2D(*grid.center(int(row), int(column)))
    return StartChoice(pose, f"{lacking}, and no point of it is {needed:.2f} m from walls and "
                             f"forbidden zones; starting at the roomiest point {_where(pose)} "
                             f"({float(clearance[row, column]):.2f} m)", invented=True)


def _free_in_area(planner: Planner, area: MapObject, needed: float) -> Pose2D | None:
    corners = area.corners()
    if corners is None:
        return None
    grid = planner.grid
    inside = np.zeros(grid.shape, bool)
    grid.fill_area(inside, area)
    middle_x, middle_y = corners.mean(axis=0)
    found = grid.nearest_clear(planner.clearance, float(middle_x), float(middle_y), needed,
                               within=inside)
    return None if found is None else Pose2D(found.x, found.y)  # theta turns the area


def _where(pose: Pose2D) -> str:
    return f"({pose.x:.2f}, {pose.y:.2f}) heading {math.degrees(pose.theta):.0f}°"
