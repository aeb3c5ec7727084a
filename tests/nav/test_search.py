"""The grid search: cheapest paths, no path where a side is closed, and a side kept closed."""

from __future__ import annotations

import heapq
import itertools
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cyborg.nav.arnl_map import parse_map
from cyborg.nav.geometry import Pose2D
from cyborg.nav.planner import Planner, SearchMemory
from cyborg.nav.search import (
    NO_LANDMARKS,
    SQRT2,
    START_SIDE,
    astar,
    landmark_costs,
    search,
    still_closed,
)
from tests.small_maps import corridor_map


def cheapest(cost: np.ndarray, start: int, goal: int) -> float:
    """Dijkstra over the moves :func:`astar` makes: the cost of a cheapest path (inf: none)."""
    rows, columns = cost.shape
    best = {start: 0.0}
    heap = [(0.0, start)]
    while heap:
        here, cell = heapq.heappop(heap)
        if cell == goal:
            return here
        if here > best[cell]:
            continue
        r, c = divmod(cell, columns)
        for dr in (-1, 0, 1):
            for dc in (-1, 0, 1):
                nr, nc = r + dr, c + dc
                if (dr, dc) == (0, 0) or not (0 <= nr < rows and 0 <= nc < columns):
                    continue
                if not math.isfinite(cost[nr, nc]):
                    continue
                if dr and dc and not (math.isfinite(cost[r, nc]) and math.isfinite(cost[nr, c])):
                    continue
                step = (SQRT2 if dr and dc else 1.0) * 0.5 * (cost[r, c] + cost[nr, nc])
                if here + step < best.get(nr * columns + nc, math.inf):
                    best[nr * columns + nc] = here + step
                    heapq.heappush(heap, (here + step, nr * columns + nc))
    return math.inf


def path_cost(cost: np.ndarray, cells: np.ndarray) -> float:
    """What a path of flat cell indices costs, each step checked to be one move."""
    columns = cost.shape[1]
    total = 0.0
    for a, b in itertools.pairwise(cells):
        (ra, ca), (rb, cb) = divmod(int(a), columns), divmod(int(b), columns)
        assert max(abs(ra - rb), abs(ca - cb)) == 1 and math.isfinite(cost[rb, cb])
        total += (SQRT2 if ra != rb and ca != cb else 1.0) * 0.5 * (cost[ra, ca] + cost[rb, cb])
    return total


@settings(max_examples=100, deadline=None)
@given(st.integers(3, 14), st.integers(3, 14), st.floats(0.0, 0.6), st.integers(0, 2**31),
       st.booleans())
def test_the_search_finds_a_cheapest_path_or_none_as_an_exhaustive_one_does(
        rows: int, columns: int, walls: float, seed: int, ring: bool) -> None:
    """Random costs and walls (with a ring of walls around the goal, sometimes with a gap):
    a path exactly when one exists, as cheap as the cheapest."""
    random = np.random.default_rng(seed)
    cost = 1.0 + random.random((rows, columns)) * 3.0
    cost[random.random((rows, columns)) < walls] = np.inf
    start, goal = int(random.integers(rows * columns)), int(random.integers(rows * columns))
    cost.flat[start] = cost.flat[goal] = 1.0
    if ring:
        gr, gc = divmod(goal, columns)
        for r in range(gr - 1, gr + 2):
            for c in range(gc - 1, gc + 2):
                if 0 <= r < rows and 0 <= c < columns and (r, c) != (gr, gc):
                    cost[r, c] = np.inf
        if random.random() < 0.5 and gr + 1 < rows:
            cost[gr + 1, gc] = 1.0  # a gap in the ring
    cells = astar(cost, start, goal)
    expected = cheapest(cost, start, goal)
    if math.isinf(expected):
        assert len(cells) == 0
    else:
        assert cells[0] == start and cells[-1] == goal
        assert path_cost(cost, cells) == np.float64(expected) or math.isclose(
            path_cost(cost, cells), expected, rel_tol=1e-9)


@settings(max_examples=100, deadline=None)
@given(st.integers(0, 2**31), st.floats(0.0, 0.4), st.integers(1, 4), st.floats(0.0, 2.0))
def test_landmarks_on_a_grid_no_dearer_find_as_cheap_a_path_or_none(
        seed: int, walls: float, count: int, dearer: float) -> None:
    """Landmarks learnt on a grid, a search on that grid made dearer and walled here and there
    (as a plan's obstacles make it): a path exactly when one exists, as cheap as the
    cheapest."""
    random = np.random.default_rng(seed)
    rows, columns = 14, 18
    cheap = 1.0 + random.random((rows, columns)) * 3.0
    cheap[random.random((rows, columns)) < walls] = np.inf
    landmarks = landmark_costs(cheap, int(random.integers(rows * columns)), count)
    cost = cheap + dearer * random.random((rows, columns))
    cost[random.random((rows, columns)) < 0.1] = np.inf
    start, goal = int(random.integers(rows * columns)), int(random.integers(rows * columns))
    cells = search(cost, start, goal, landmarks)[0]
    expected = cheapest(cost, start, goal)
    if math.isinf(expected) or not math.isfinite(cost.flat[goal]):
        assert len(cells) == 0 or start == goal
    else:
        assert cells[0] == start and cells[-1] == goal
        assert path_cost(cost, cells) == pytest.approx(expected, rel=1e-4, abs=0.05)


def test_a_goal_on_a_closed_side_has_no_path_and_an_open_one_has() -> None:
    """A wall across a corridor with the goal in a room behind it: no path, both ways round;
    a gap in it: the path goes through the gap."""
    cost = np.ones((40, 200))
    cost[:, 20] = np.inf  # the start's side is the map less a room of 40 x 20 cells
    start, goal = 5 * 200 + 150, 20 * 200 + 5
    assert len(astar(cost, start, goal)) == 0
    assert len(astar(cost, goal, start)) == 0
    cost[30, 20] = 1.0
    cells = astar(cost, start, goal)
    assert cells[0] == start and cells[-1] == goal and 30 * 200 + 20 in cells


@settings(max_examples=100, deadline=None)
@given(st.integers(0, 2**31), st.integers(0, 30), st.integers(0, 30))
def test_a_side_still_closed_after_changes_has_no_path_indeed(seed: int, opened: int,
                                                               closed: int) -> None:
    """A search that found no path, then cells opened and closed at random: when its side is
    said to be still closed, a search finds no path either; when one does, it was not said."""
    random = np.random.default_rng(seed)
    rows, columns = 12, 16
    cost = 1.0 + random.random((rows, columns))
    cost[:, 7] = np.inf  # a wall across, with the start west of it and the goal east
    cost[random.random((rows, columns)) < 0.2] = np.inf
    start, goal = 5 * columns + 2, 6 * columns + 12
    cost.flat[start] = cost.flat[goal] = 1.0
    cells, region, side = search(cost, start, goal, NO_LANDMARKS)
    if len(cells):
        return
    passable, region = np.isfinite(cost), region.reshape(cost.shape).copy()
    later = cost.copy()
    for index in random.integers(rows * columns, size=opened):
        later.flat[index] = 1.0
    for index in random.integers(rows * columns, size=closed):
        later.flat[index] = np.inf
    later.flat[start] = later.flat[goal] = 1.0
    target = goal if side == START_SIDE else start
    if still_closed(later, passable, region, target):
        assert len(astar(later, start, goal)) == 0
    assert np.array_equal(passable, np.isfinite(later))


def test_a_planner_with_memory_answers_as_without_and_searches_less() -> None:
    """A robot waiting behind a person in a corridor asks every second: the same answers, with
    or without memory; with it, a search only when the person stepped away."""
    planner = Planner(parse_map(corridor_map(1.6)))
    memory = SearchMemory()
    start, goal = Pose2D(1.0, 0.8), Pose2D(13.0, 0.8)
    people = [(6.0, 0.8)] * 5 + [(6.0, 0.85)] * 3 + [(6.0, 3.0)] + [(7.0, 0.8)] * 3
    for x, y in people:
        discs = np.array([(x, y, 0.4)])
        with_memory = planner.plan(start, goal, discs=discs, memory=memory)
        without = planner.plan(start, goal, discs=discs)
        assert (with_memory.code, with_memory.length) == (without.code, without.length)
    assert memory.searches < len(people) - 4
