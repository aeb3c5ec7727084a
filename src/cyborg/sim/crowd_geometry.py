"""The crowd's compiled geometry: who walks into whom, and whether a straight walk clears walls.

:class:`~cyborg.sim.people.Crowd` asks these for every person at every step, so they are numba
kernels on plain arrays rather than Python loops over people.
"""

from __future__ import annotations

import heapq
import math

import numpy as np
from numba import njit

SQRT2 = math.sqrt(2.0)


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


@njit(cache=True)
def way_off(clearance: np.ndarray, origin_x: float, origin_y: float, resolution: float,
            x: float, y: float, need: float, reach: float, ways: np.ndarray, room: float,
            bodies: np.ndarray) -> np.ndarray:  # pragma: no cover - jit
    """The shortest walk from ``(x, y)`` to a place ``room`` m off every point of ``ways``.

    The walk goes cell by cell (8-connected, a diagonal step only between two open cells) over
    cells at least ``need`` m from walls (the ``clearance`` grid's; cell (0, 0)'s corner at the
    origin), at most ``reach`` m long, and never closer to one of ``bodies`` ((M, 3):
    x, y, radius of a body to keep ``radius`` m from) than that or than the start is; it ends
    in the first cell whose centre is ``room`` m or more from every point of ``ways`` ((N, 2)).
    Returns the cell centres after the start, (K, 2) m; empty when no such place is in reach.
    """
    rows, columns = clearance.shape
    row, column = math.floor((y - origin_y) / resolution), math.floor((x - origin_x) / resolution)
    span = math.ceil(reach / resolution)
    r0, c0 = max(row - span, 0), max(column - span, 0)
    r1, c1 = min(row + span + 1, rows), min(column + span + 1, columns)
    if not (r0 <= row < r1 and c0 <= column < c1):
        return np.zeros((0, 2))
    height, width = r1 - r0, c1 - c0
    start_gap = np.empty(bodies.shape[0])
    for k in range(bodies.shape[0]):
        start_gap[k] = math.hypot(x - bodies[k, 0], y - bodies[k, 1])
    known = np.zeros((height, width), np.int8)  # 0 unknown, 1 walkable, -1 not
    parent = np.full(height * width, -1, np.int64)
    walked = np.full(height * width, np.inf)
    first = (row - r0) * width + column - c0
    parent[first], walked[first] = first, 0.0
    heap = [(0.0, first)]
    found = -1
    while len(heap) > 0:
        far, cell = heapq.heappop(heap)
        if far > walked[cell]:
            continue
        r, c = cell // width, cell % width
        cx = origin_x + (c + c0 + 0.5) * resolution
        cy = origin_y + (r + r0 + 0.5) * resolution
        if cell != first and _off_ways(ways, cx, cy, room):
            found = cell
            break
        for dr in range(-1, 2):
            for dc in range(-1, 2):
                nr, nc = r + dr, c + dc
                if (dr == 0 and dc == 0) or nr < 0 or nr >= height or nc < 0 or nc >= width:
                    continue
                nxt = nr * width + nc
                further = far + (SQRT2 if dr != 0 and dc != 0 else 1.0) * resolution
                if further >= walked[nxt] or further > reach or not _walkable(
                        known, clearance, nr, nc, r0, c0, origin_x, origin_y, resolution, need,
                        bodies, start_gap):
                    continue
                if dr != 0 and dc != 0 and not (
                        _walkable(known, clearance, r, nc, r0, c0, origin_x, origin_y,
                                  resolution, need, bodies, start_gap)
                        and _walkable(known, clearance, nr, c, r0, c0, origin_x, origin_y,
                                      resolution, need, bodies, start_gap)):
                    continue
                parent[nxt], walked[nxt] = cell, further
                heapq.heappush(heap, (further, nxt))
    if found < 0:
        return np.zeros((0, 2))
    return _walk_to(parent, first, found, width, r0, c0, origin_x, origin_y, resolution)


@njit(cache=True)
def _off_ways(ways: np.ndarray, x: float, y: float,
              room: float) -> bool:  # pragma: no cover - jit
    """Whether ``(x, y)`` is ``room`` m or more from every point of ``ways`` ((N, 2))."""
    for k in range(ways.shape[0]):
        if (ways[k, 0] - x) ** 2 + (ways[k, 1] - y) ** 2 < room * room:
            return False
    return True


@njit(cache=True)
def _walk_to(parent: np.ndarray, first: int, found: int, width: int, r0: int, c0: int,
             origin_x: float, origin_y: float,
             resolution: float) -> np.ndarray:  # pragma: no cover - jit
    """The centres of the window cells from after ``first`` to ``found``, by ``parent``."""
    length = 0
    cell = found
    while cell != first:
        cell = parent[cell]
        length += 1
    walk = np.empty((length, 2))
    cell = found
    for index in range(length - 1, -1, -1):
        walk[index, 0] = origin_x + (cell % width + c0 + 0.5) * resolution
        walk[index, 1] = origin_y + (cell // width + r0 + 0.5) * resolution
        cell = parent[cell]
    return walk


@njit(cache=True)
def _walkable(known: np.ndarray, clearance: np.ndarray, r: int, c: int, r0: int, c0: int,
              origin_x: float, origin_y: float, resolution: float, need: float,
              bodies: np.ndarray, start_gap: np.ndarray) -> bool:  # pragma: no cover - jit
    """Whether :func:`way_off` may step into window cell ``(r, c)`` (worked out once, kept)."""
    if known[r, c] == 0:
        known[r, c] = 1 if clearance[r + r0, c + c0] >= need else -1
        if known[r, c] == 1:
            cx = origin_x + (c + c0 + 0.5) * resolution
            cy = origin_y + (r + r0 + 0.5) * resolution
            for k in range(bodies.shape[0]):
                gap = math.hypot(cx - bodies[k, 0], cy - bodies[k, 1])
                if gap < bodies[k, 2] and gap < start_gap[k]:
                    known[r, c] = -1
                    break
    return bool(known[r, c] == 1)
