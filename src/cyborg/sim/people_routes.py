"""The routes people walk between two points of the map, planned once and kept.

People repeat their legs (waypoint to waypoint, round and round), and random people share the
map's goals, so a :class:`RouteBook` plans each leg once with the navigation planner (which
keeps the robot's clearance from walls and forbidden zones) and hands out the kept route
afterwards; the way back is the way there reversed.
"""

from __future__ import annotations

import numpy as np

from cyborg.nav.geometry import Pose2D
from cyborg.nav.planner import Planner

Point = tuple[float, float]
"""A point of the map, (x, y) in metres."""


class RouteBook:
    """Routes between points on the map, planned once each and kept (people repeat their legs).

    A route is the planner's path from one point to another, (K, 2) metres, its first point
    the start; None when the planner finds none (kept too: it would not find one again). The
    way back is the way there reversed, not planned again.
    """

    def __init__(self, planner: Planner) -> None:
        self.planner = planner
        self._routes: dict[tuple[float, float, float, float], np.ndarray | None] = {}
        self.planned = 0

    def route(self, start: Point, goal: Point) -> np.ndarray | None:
        """The way from ``start`` to ``goal`` (rounded to the centimetre), or None."""
        key = (round(start[0], 2), round(start[1], 2), round(goal[0], 2), round(goal[1], 2))
        if key not in self._routes:
            reverse = (key[2], key[3], key[0], key[1])
            if reverse in self._routes:  # the way back is the way there, reversed
                back = self._routes[reverse]
                self._routes[key] = None if back is None else back[::-1].copy()
            else:
                self.planned += 1
                result = self.planner.plan(Pose2D(*start), Pose2D(*goal))
                self._routes[key] = None if result.path is None else result.path.points.copy()
        return self._routes[key]
