"""Compiled grid search kernels (numba): A* on a cost grid and line-of-sight checks.

These are the hot loops of planning; :mod:`cyborg.nav.planner` wraps them. Costs are per cell:
``inf`` is impassable, otherwise the price of one metre through the cell (≥ 1). Moves go to the
8 neighbours; a diagonal move costs sqrt(2) times the mean of the two cells' costs, so paths are
truly shortest (no zig-zag bias), and the octile distance is an admissible heuristic.

The first call compiles the kernels (about a second); the result is cached on disk.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

SQRT2 = math.sqrt(2.0)
FLOOD_EVERY = 1
"""Steps of the search per step of :func:`astar`'s flood from the goal."""
LANDMARK_SLACK = 0.01
"""Cost taken off a landmark's estimate: more than float32 rounds costs of 100,000 cells."""
NO_LANDMARKS = np.zeros((0, 0), np.float32)
"""No landmarks: the octile estimate alone."""


NOWHERE = 0
"""What :func:`search` says of its region when it found a path (or learned nothing)."""
START_SIDE = 1
"""The region :func:`search` returns is every cell the start reaches (not the goal)."""
GOAL_SIDE = 2
"""The region :func:`search` returns is every cell that reaches the goal (not the start)."""


@njit(cache=True)
def astar(cost: np.ndarray, start: int, goal: int) -> np.ndarray:  # pragma: no cover - jit
    """Cells (flat indices) of a cheapest 8-connected path from start to goal; empty if none.

    See :func:`search`.
    """
    return search(cost, start, goal, NO_LANDMARKS)[0]


@njit(cache=True)
def search(cost: np.ndarray, start: int, goal: int,
           landmarks: np.ndarray) -> tuple[np.ndarray, np.ndarray, int]:  # pragma: no cover
    """:func:`astar`'s path, and without one the side it found closed: ``(path, region, side)``.

    ``landmarks`` ((cells, K), float32; K may be 0) are the costs from every cell to K
    landmarks on a grid no dearer than ``cost`` anywhere (:func:`landmark_costs`): the
    estimate of what is left from a cell is then at least the largest difference of its cost
    and the goal's to a landmark (less :data:`LANDMARK_SLACK` for rounding), which is never
    more than it costs (the triangle inequality), so the path is as cheap; and a cell that
    reaches no landmark the goal reaches, or the other way round, cannot reach the goal.

    ``region`` (flat booleans) is the start's side (``side`` :data:`START_SIDE`: every cell
    the start reaches) or the goal's (:data:`GOAL_SIDE`: every cell that reaches the goal),
    whichever the search closed first; :data:`NOWHERE` with a path (or a goal that cannot be
    entered).

    The open cells wait in a binary heap ordered by estimate, then cell (so ties go the same
    way every time). Beside the search, one step in :data:`FLOOD_EVERY`, a flood from the goal
    goes back over the cells from which the goal can be reached: when it runs out before it
    reaches the start, there is no path, and the search stops there rather than visit every
    cell it can reach (a goal in a room whose door is taken costs the room, not the map).
    """
    rows, columns = cost.shape
    flat = cost.ravel()
    size = rows * columns
    g = np.full(size, np.inf)
    parent = np.full(size, -1, np.int64)
    closed = np.zeros(size, np.bool_)
    goal_r, goal_c = goal // columns, goal % columns
    g[start] = 0.0
    capacity = 1024
    keys = np.empty(capacity)
    cells = np.empty(capacity, np.int64)
    keys[0], cells[0], count = 0.0, start, 1
    if goal != start and not np.isfinite(flat[goal]):
        return np.zeros(0, np.int64), closed, NOWHERE  # it enters finite cells only
    to_goal = landmarks[goal] if landmarks.shape[1] else np.zeros(0, np.float32)
    back = np.zeros(size, np.bool_)  # the flood from the goal
    queue = np.empty(size, np.int64)
    queue[0], back[goal], head, tail = goal, True, 0, 1
    flooding = goal != start
    turn = 0
    while count > 0:
        turn += 1
        if flooding and turn % FLOOD_EVERY == 0:
            if head == tail:  # the goal's side is closed, without the start in it
                return np.zeros(0, np.int64), back, GOAL_SIDE
            tail = _flood(flat, rows, columns, back, queue, head, tail)
            head += 1
            flooding = not back[start]
        current = cells[0]
        count -= 1
        if count > 0:
            _sift_down(keys, cells, count)
        if closed[current]:
            continue
        if current == goal:
            break
        closed[current] = True
        r, c = current // columns, current % columns
        here = flat[current]
        base = g[current]
        for k in range(8):
            dr, dc = _DR[k], _DC[k]
            nr, nc = r + dr, c + dc
            if nr < 0 or nr >= rows or nc < 0 or nc >= columns:
                continue
            neighbour = nr * columns + nc
            there = flat[neighbour]
            if closed[neighbour] or not np.isfinite(there):
                continue
            diagonal = dr != 0 and dc != 0
            if diagonal and (not np.isfinite(flat[r * columns + nc])
                             or not np.isfinite(flat[nr * columns + c])):
                continue  # never squeeze between two blocked cells
            step = (SQRT2 if diagonal else 1.0) * 0.5 * (here + there)
            candidate = base + step
            if candidate < g[neighbour]:
                g[neighbour] = candidate
                parent[neighbour] = current
                ar, ac = abs(nr - goal_r), abs(nc - goal_c)
                h = _beyond(landmarks, to_goal, neighbour,
                            (SQRT2 - 1.0) * min(ar, ac) + max(ar, ac))
                if h == np.inf:
                    continue  # on no side of the goal's landmarks: it cannot reach the goal
                if count == capacity:
                    capacity *= 2
                    keys, cells = _grown(keys, count, capacity), _grown(cells, count, capacity)
                _sift_up(keys, cells, count, candidate + h, neighbour)
                count += 1
    if parent[goal] < 0 and goal != start:
        return np.zeros(0, np.int64), closed, START_SIDE
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
    return path, closed, NOWHERE


@njit(cache=True)
def still_closed(cost: np.ndarray, passable: np.ndarray, region: np.ndarray,
                 target: int) -> bool:  # pragma: no cover - jit
    """Whether a side :func:`search` found closed on a cost grid is still closed on ``cost``.

    ``passable`` (booleans, the grid's shape) are the cells that were finite then, ``region``
    the side then (as :func:`search` gave it, or grown here since), ``target`` the cell it did
    not hold (the goal for the start's side, the start for the goal's). Whatever changed, the
    side can now only hold its cells and those it reaches through cells newly finite next to
    it; when those do not take in ``target``, no path can pass: True. Both are brought up to
    ``cost`` (``region`` grown by what was reached), to be asked again after the next change.
    The cells at either end must be finite (or not) as they were.
    """
    rows, columns = cost.shape
    flat, was, inside = cost.ravel(), passable.ravel(), region.ravel()
    queue = np.empty(rows * columns, np.int64)
    tail = 0
    for cell in range(rows * columns):
        now = np.isfinite(flat[cell])
        if now and not was[cell] and not inside[cell] and _beside(flat, inside, rows, columns,
                                                                   cell):
            inside[cell] = True
            queue[tail] = cell
            tail += 1
        was[cell] = now
    head = 0
    while head < tail:
        cell = queue[head]
        head += 1
        if cell == target:
            return False
        r, c = cell // columns, cell % columns
        for k in range(8):
            dr, dc = _DR[k], _DC[k]
            nr, nc = r + dr, c + dc
            if nr < 0 or nr >= rows or nc < 0 or nc >= columns:
                continue
            neighbour = nr * columns + nc
            if inside[neighbour] or not np.isfinite(flat[neighbour]):
                continue
            if dr != 0 and dc != 0 and (not np.isfinite(flat[r * columns + nc])
                                        or not np.isfinite(flat[nr * columns + c])):
                continue
            inside[neighbour] = True
            queue[tail] = neighbour
            tail += 1
    return True


@njit(cache=True)
def _beside(flat: np.ndarray, inside: np.ndarray, rows: int, columns: int,
            cell: int) -> bool:  # pragma: no cover - jit
    """Whether one step joins finite ``cell`` and a cell ``inside`` (as :func:`astar` steps)."""
    r, c = cell // columns, cell % columns
    for k in range(8):
        dr, dc = _DR[k], _DC[k]
        nr, nc = r + dr, c + dc
        if nr < 0 or nr >= rows or nc < 0 or nc >= columns or not inside[nr * columns + nc]:
            continue
        if dr != 0 and dc != 0 and (not np.isfinite(flat[r * columns + nc])
                                    or not np.isfinite(flat[nr * columns + c])):
            continue
        return True
    return False


@njit(cache=True)
def _beyond(landmarks: np.ndarray, to_goal: np.ndarray, cell: int,
            octile: float) -> float:  # pragma: no cover - jit
    """The estimate of what is left from ``cell``: the octile distance, or the landmarks'."""
    estimate = octile
    for k in range(to_goal.shape[0]):
        here, there = landmarks[cell, k], to_goal[k]
        if np.isfinite(here) and np.isfinite(there):
            estimate = max(estimate, abs(here - there) - LANDMARK_SLACK)
        elif np.isfinite(here) != np.isfinite(there):
            return np.inf
    return estimate


@njit(cache=True)
def landmark_costs(cost: np.ndarray, first: int, count: int) -> np.ndarray:  # pragma: no cover
    """The costs from every cell to ``count`` landmarks of ``cost``: (cells, count), float32.

    The landmarks lie far apart: the first is the cell dearest to reach from ``first``, each
    next the one whose cheapest way to the landmarks so far is dearest (inf: not reached).
    Steps as :func:`astar` takes them.
    """
    size = cost.size
    found = np.full((size, count), np.inf, np.float32)
    nearest = _costs_from(cost, first)
    for k in range(count):
        landmark, dearest = -1, -1.0
        for cell in range(size):
            if np.isfinite(nearest[cell]) and nearest[cell] > dearest:
                landmark, dearest = cell, nearest[cell]
        if landmark < 0:
            break
        costs = _costs_from(cost, landmark)
        for cell in range(size):
            found[cell, k] = costs[cell]
            nearest[cell] = costs[cell] if k == 0 else min(nearest[cell], costs[cell])
    return found


@njit(cache=True)
def _costs_from(cost: np.ndarray, source: int) -> np.ndarray:  # pragma: no cover - jit
    """The cheapest cost from ``source`` to every cell (Dijkstra, :func:`astar`'s steps)."""
    rows, columns = cost.shape
    flat = cost.ravel()
    g = np.full(rows * columns, np.inf)
    g[source] = 0.0
    capacity = 1024
    keys = np.empty(capacity)
    cells = np.empty(capacity, np.int64)
    keys[0], cells[0], count = 0.0, source, 1
    while count > 0:
        current, far = cells[0], keys[0]
        count -= 1
        if count > 0:
            _sift_down(keys, cells, count)
        if far > g[current]:
            continue
        r, c = current // columns, current % columns
        here = flat[current]
        for k in range(8):
            dr, dc = _DR[k], _DC[k]
            nr, nc = r + dr, c + dc
            if nr < 0 or nr >= rows or nc < 0 or nc >= columns:
                continue
            neighbour = nr * columns + nc
            there = flat[neighbour]
            if not np.isfinite(there):
                continue
            diagonal = dr != 0 and dc != 0
            if diagonal and (not np.isfinite(flat[r * columns + nc])
                             or not np.isfinite(flat[nr * columns + c])):
                continue
            candidate = far + (SQRT2 if diagonal else 1.0) * 0.5 * (here + there)
            if candidate < g[neighbour]:
                g[neighbour] = candidate
                if count == capacity:
                    capacity *= 2
                    keys, cells = _grown(keys, count, capacity), _grown(cells, count, capacity)
                _sift_up(keys, cells, count, candidate, neighbour)
                count += 1
    return g


_DR = (-1, -1, -1, 0, 0, 1, 1, 1)
_DC = (-1, 0, 1, -1, 1, -1, 0, 1)


@njit(cache=True)
def _flood(flat: np.ndarray, rows: int, columns: int, back: np.ndarray, queue: np.ndarray,
           head: int, tail: int) -> int:  # pragma: no cover - jit
    """Take ``queue[head]`` and queue the cells from which the search may step onto it.

    Those are its finite neighbours not in ``back`` yet (a diagonal one only between two
    finite cells, as :func:`astar` steps); they join ``back``. Returns the queue's new tail.
    """
    cell = queue[head]
    r, c = cell // columns, cell % columns
    for k in range(8):
        dr, dc = _DR[k], _DC[k]
        nr, nc = r + dr, c + dc
        if nr < 0 or nr >= rows or nc < 0 or nc >= columns:
            continue
        neighbour = nr * columns + nc
        if back[neighbour] or not np.isfinite(flat[neighbour]):
            continue
        if dr != 0 and dc != 0 and (not np.isfinite(flat[r * columns + nc])
                                    or not np.isfinite(flat[nr * columns + c])):
            continue
        back[neighbour] = True
        queue[tail] = neighbour
        tail += 1
    return tail


@njit(cache=True)
def _sift_down(keys: np.ndarray, cells: np.ndarray, count: int) -> None:  # pragma: no cover
    """Put the heap's entry ``count`` (just past its end) in place of its root, in order."""
    key, cell = keys[count], cells[count]
    i = 0
    while True:
        child = 2 * i + 1
        if child >= count:
            break
        if child + 1 < count and (keys[child + 1] < keys[child] or (
                keys[child + 1] == keys[child] and cells[child + 1] < cells[child])):
            child += 1
        if keys[child] < key or (keys[child] == key and cells[child] < cell):
            keys[i], cells[i] = keys[child], cells[child]
            i = child
        else:
            break
    keys[i], cells[i] = key, cell


@njit(cache=True)
def _sift_up(keys: np.ndarray, cells: np.ndarray, count: int, key: float,
             cell: int) -> None:  # pragma: no cover - jit
    """Add ``(key, cell)`` to the heap of ``count`` entries, in order."""
    i = count
    while i > 0:
        up = (i - 1) >> 1
        if key < keys[up] or (key == keys[up] and cell < cells[up]):
            keys[i], cells[i] = keys[up], cells[up]
            i = up
        else:
            break
    keys[i], cells[i] = key, cell


@njit(cache=True)
def _grown(values: np.ndarray, count: int, capacity: int) -> np.ndarray:  # pragma: no cover
    """A copy of ``values``' first ``count`` entries with room for ``capacity``."""
    more = np.empty(capacity, values.dtype)
    more[:count] = values[:count]
    return more


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
