"""The crowd's compiled geometry: who walks into whom, and whether a straight walk clears walls.

:class:`~cyborg.sim.people.Crowd` asks these for every person at every step, so they are numba
kernels on plain arrays rather than Python loops over people.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def in_the_way(here: np.ndarray, people: np.ndarray, radius: float, robots: np.ndarray,
               look_ahead: float) -> np.ndarray:  # pragma: no cover - jit
    """For each walker (x, y, heading): whether a person or a robot is ahead of them.

    ``people`` are (N, 2) positions of bodies of ``radius`` m (the walkers among them),
    ``robots`` (M, 3) rows of x, y, radius. Ahead: along the heading by more than nothing and
    at most both radii plus ``look_ahead``, and less than both radii plus 10 cm aside. A
    walker never blocks itself (distance 0).
    """
    result = np.zeros(here.shape[0], np.bool_)
    count = people.shape[0]
    for walker in range(here.shape[0]):
        ux, uy = math.cos(here[walker, 2]), math.sin(here[walker, 2])
        for other in range(count + robots.shape[0]):
            if other < count:
                ox, oy, reach = people[other, 0], people[other, 1], 2 * radius
            else:
                row = other - count
                ox, oy, reach = robots[row, 0], robots[row, 1], radius + robots[row, 2]
            rx, ry = ox - here[walker, 0], oy - here[walker, 1]
            along = rx * ux + ry * uy
            across = abs(rx * uy - ry * ux)
            if 1e-9 < along <= reach + look_ahead and across < reach + 0.1:
                result[walker] = True
                break
    return result


@njit(cache=True)
def in_robots_way(people: np.ndarray, x: float, y: float, need: float, heading: float,
                  ahead: float) -> np.ndarray:  # pragma: no cover - jit
    """Which of ``people`` ((N, 2) positions) must make room for a robot at ``(x, y)``.

    Those closer than ``need`` m (centre to centre), and, with a finite ``heading`` (rad; nan
    for none), those ahead of it: along the heading by more than nothing and at most
    ``ahead`` m, and less than ``need`` aside.
    """
    result = np.zeros(people.shape[0], np.bool_)
    ux, uy = math.cos(heading), math.sin(heading)
    for index in range(people.shape[0]):
        dx, dy = people[index, 0] - x, people[index, 1] - y
        if math.hypot(dx, dy) < need:
            result[index] = True
        elif not math.isnan(heading):
            along, across = dx * ux + dy * uy, uy * dx - ux * dy
            result[index] = 0.0 < along <= ahead and abs(across) < need
    return result


@njit(cache=True)
def line_clear(clearance: np.ndarray, origin_x: float, origin_y: float, resolution: float,
                x0: float, y0: float, x1: float, y1: float,
                need: float) -> bool:  # pragma: no cover - jit
    """Whether a straight walk from ``(x0, y0)`` to ``(x1, y1)`` keeps ``need`` m from walls.

    Points every 10 cm (or less) along it are looked up in the ``clearance`` grid (metres to
    the nearest wall per cell; cell (0, 0)'s corner at the origin); points off the grid count
    as the nearest edge cell. The first point too close ends the walk.
    """
    rows, columns = clearance.shape
    steps = max(2, math.ceil(math.hypot(x1 - x0, y1 - y0) / 0.1))
    for k in range(steps):
        share = k / (steps - 1)
        row = math.floor((y0 + share * (y1 - y0) - origin_y) / resolution)
        column = math.floor((x0 + share * (x1 - x0) - origin_x) / resolution)
        if clearance[min(max(row, 0), rows - 1), min(max(column, 0), columns - 1)] < need:
            return False
    return True
