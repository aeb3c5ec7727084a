"""The crowd's compiled geometry: who walks into whom, and whether a straight walk clears walls.

:class:`~cyborg.sim.people.Crowd` asks these for every person at every step, so they are numba
kernels on plain arrays rather than Python loops over people.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def in_the_way(here: np.ndarray, others: np.ndarray, radius: float,
                look_ahead: float) -> np.ndarray:  # pragma: no cover - jit
    """For each walker (x, y, heading): whether one of ``others`` (x, y, radius) is ahead.

    Ahead: along the heading by more than nothing and at most both radii plus ``look_ahead``,
    and less than both radii plus 10 cm aside. A walker never blocks itself (distance 0).
    """
    result = np.zeros(here.shape[0], np.bool_)
    for walker in range(here.shape[0]):
        ux, uy = math.cos(here[walker, 2]), math.sin(here[walker, 2])
        for other in range(others.shape[0]):
            rx, ry = others[other, 0] - here[walker, 0], others[other, 1] - here[walker, 1]
            along = rx * ux + ry * uy
            across = abs(rx * uy - ry * ux)
            reach = radius + others[other, 2]
            if 1e-9 < along <= reach + look_ahead and across < reach + 0.1:
                result[walker] = True
                break
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
