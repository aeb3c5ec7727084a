"""Compiled grid search kernels (numba): A* on a cost grid and line-of-sight checks.

These are the hot loops of planning; :mod:`cyborg.nav.planner` wraps them. Costs are per cell:
``inf`` is impassable, otherwise the price of one metre through the cell (≥ 1). Moves go to the
8 neighbours; a diagonal move costs sqrt(2) times the mean of the two cells' costs, so paths are
truly shortest (no zig-zag bias), and the octile distance is an admissible heuristic.

The first call compiles the kernels (about a second); the result is cached on disk.
"""

from __future__ import annotations

import heapq
import math

import numpy as np
from numba import njit

SQRT2 = math.sqrt(2.0)


@njit(cache=True)
def astar(cost: np.ndarray, start: int, goal: int) -> np.ndarray:  # pragma: no cover - jit
    """Cells (flat indices) of a cheapest 8-connected path from start to goal; empty if none."""
    rows, columns = cost.shape
    flat = cost.ravel()
    size = rows * columns
    g = np.full(size, np.inf)
    parent = np.full(size, -1, np.int64)
    closed = np.zeros(size, np.bool_)
    goal_r, goal_c = goal // columns, goal % columns
    g[start] = 0.0
    heap = [(0.0, start)]
    dr = np.array([-1, -1, -1, 0, 0, 1, 1, 1])
    dc = np.array([-1, 0, 1, -1, 1, -1, 0, 1])
    while len(heap) > 0:
        _f, current = heapq.heappop(heap)
        if closed[current]:
            continue
        if current == goal:
            break
        closed[current] = True
        r, c = current // columns, current % columns
        here = flat[current]
        for k in range(8):
            nr, nc = r + dr[k], c + dc[k]
            if nr < 0 or nr >= rows or nc < 0 or nc >= columns:
                continue
            neighbour = nr * columns + nc
            there = flat[neighbour]
            if closed[neighbour] or not np.isfinite(there):
                continue
            diagonal = dr[k] != 0 and dc[k] != 0
            if diagonal and (not np.isfinite(flat[r * columns + nc])
                             or not np.isfinite(flat[nr * columns + c])):
                continue  # never squeeze between two blocked cells
            step = (SQRT2 if diagonal else 1.0) * 0.5 * (here + there)
            candidate = g[current] + step
            if candidate < g[neighbour]:
                g[neighbour] = candidate
                parent[neighbour] = current
                ar, ac = abs(nr - goal_r), abs(nc - goal_c)
                h = (SQRT2 - 1.0) * min(ar, ac) + max(ar, ac)
                heapq.heappush(heap, (candidate + h, neighbour))
    if parent[goal] < 0 and goal != start:
        return np.zeros(0, np.int64)
    length = 1
    cell = goal
    while cell != start:
        cell = parent[cell]
        length += 1
    path = np.empty(length, np.int64)
    cell = goal
    for index in range(length - 1, -1, -1):
        path[index] = cell
        cell = parent[cell]
    return path


@njit(cache=True)
def segment_clearance(clearance: np.ndarray, origin_x: float, origin_y: float,
                      resolution: float, x0: float, y0: float, x1: float,
                      y1: float) -> float:  # pragma: no cover - jit
    """The smallest clearance of the cells a straight segment passes (sampled at 1/3 cell)."""
    rows, columns = clearance.shape
    length = math.hypot(x1 - x0, y1 - y0)
    steps = max(1, math.ceil(length / (resolution / 3.0)))
    lowest = np.inf
    for i in range(steps + 1):
        t = i / steps
        x = x0 + (x1 - x0) * t
        y = y0 + (y1 - y0) * t
        r = math.floor((y - origin_y) / resolution)
        c = math.floor((x - origin_x) / resolution)
        if r < 0 or r >= rows or c < 0 or c >= columns:
            return 0.0
        value = clearance[r, c]
        if value < lowest:
            lowest = value
    return lowest


@njit(cache=True)
def shortcut(points: np.ndarray, floors: np.ndarray, clearance: np.ndarray, origin_x: float,
             origin_y: float, resolution: float, margin: float) -> np.ndarray:  # pragma: no cover
    """Indices of the points kept when cutting corners by line of sight.

    From each kept point, jump as far along the path as the straight segment keeps a
    clearance of at least ``min(margin, floor)``, where ``floor`` is the smallest clearance the
    grid path had between the two points: a shortcut never runs closer to walls than the search
    path did, nor closer than ``margin`` where the search path had room.
    """
    count = len(points)
    kept = [0]
    i = 0
    while i < count - 1:
        best = i + 1
        lowest = floors[i + 1]
        for j in range(i + 2, count):
            if floors[j] < lowest:
                lowest = floors[j]
            need = min(margin, lowest) - 1e-6
            if segment_clearance(clearance, origin_x, origin_y, resolution, points[i, 0],
                                 points[i, 1], points[j, 0], points[j, 1]) >= need:
                best = j
            else:
                break  # greedy: the first blocked view ends the jump
        kept.append(best)
        i = best
    return np.array(kept, np.int64)
