"""Path planning on an ARNL map: a grid search that keeps the robot clear of walls.

As ARNL does, the map (points, lines, forbidden lines and areas) is sampled into a grid (5 cm by
default); A* finds the cheapest path whose cells keep the robot's *circumscribed* radius from
anything blocked, with a cost that rises near walls so paths keep to the middle of corridors; then
line-of-sight shortcuts straighten it without coming closer to walls than the search path did.

Poses near walls (the dock, a goal in a niche) are reachable: around the start and the goal the
robot may use cells that only clear its *inscribed* radius. A goal whose pose does not even
clear that ("inside a wall"), lies in a forbidden zone, or is cut off gives a result without a
path, whose ``code`` uses Nav2's names and whose ``length`` is infinity::

    planner = Planner(read_map("columbia.map"))
    result = planner.plan(Pose2D(0, 0), Pose2D(13.0, -12.2))
    result.found, result.length, result.reason

Objects seen lately (people, :mod:`cyborg.nav.temporary_obstacles`) are planned around as
*discs*: each is stamped into copies of the cached clearance and cost grids (a window around
the disc, nothing rebuilt), so the robot's centre keeps the disc's keep-out radius plus its
circumscribed radius from the centre, with the same cost ramp as near walls. A disc holding
the start or the goal is shrunk until that pose lies just outside it (never ``GOAL_OCCUPIED``
because someone stands there).
"""

from __future__ import annotations

import math
import threading
import time
from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from cyborg.nav.arnl_map import ArnlMap
from cyborg.nav.footprint import PIONEER_LX, Footprint
from cyborg.nav.geometry import Path, Pose2D
from cyborg.nav.grid import MapGrid
from cyborg.nav.search import (
    NO_LANDMARKS,
    START_SIDE,
    astar,
    landmark_costs,
    search,
    shortcut,
    still_closed,
)
from cyborg.nav.temporary_obstacles import clear_of


@dataclass(frozen=True)
class PlannerSettings:
    """Tuning of the planner; lengths in metres (ARNL's names in brackets)."""

    resolution: float = 0.05  # grid cell size [PlanRes]
    padding: float = 0.0  # clearance beyond the circumscribed radius [PlanFreeSpace]
    cost_ramp: float = 0.4  # how far beyond that the cost of being near walls reaches
    cost_weight: float = 3.0  # the extra cost per metre right at the lethal distance
    smoothing_margin: float = 0.55  # clearance shortcuts keep where the grid path had it
    escape_radius: float = 0.8  # around start and goal, cells clearing the inscribed radius


LANDMARKS = 8
"""Landmarks a planner that plans often estimates its searches by (see :func:`~cyborg.nav.
search.search`)."""
LANDMARK_BYTES = 32 * 1024 * 1024
"""The most memory a planner's landmarks take: fewer landmarks on a larger map, none past
about a million cells."""
LANDMARKS_AFTER = 20
"""Plans after which a planner learns its landmarks (a second or so on the campus): one that
plans a few times only never pays for them."""

Window = tuple[slice, slice]
"""Rows and columns of a grid: what a plan changed in the scratch grids."""

# Result codes (Nav2's ComputePathToPose error names).
NONE, START_OCCUPIED, GOAL_OCCUPIED, NO_VALID_PATH, OUTSIDE_MAP = (
    "NONE", "START_OCCUPIED", "GOAL_OCCUPIED", "NO_VALID_PATH", "START_OUTSIDE_MAP")


@dataclass(frozen=True)
class PlanResult:
    """A path, or why there is none (``code`` and ``reason``); how long planning took.

    ``code`` is one of this module's result codes (Nav2's names), ``NONE`` when a path was
    found; ``planning_time`` is in seconds.
    """

    path: Path | None
    code: str = NONE
    reason: str = ""
    planning_time: float = 0.0

    @property
    def found(self) -> bool:
        """Whether there is a path."""
        return self.path is not None

    @property
    def length(self) -> float:
        """Metres along the path; infinity without one."""
        return self.path.length if self.path is not None else math.inf


@dataclass
class ClosedSide:
    """What a plan that found no path learned: the side of start or goal it found closed.

    ``goal`` is the flat cell planned to, ``passable`` the cells that were finite, ``region``
    the closed side (:func:`~cyborg.nav.search.search`'s), ``from_start`` whether it is the
    start's side.
    """

    goal: int
    passable: np.ndarray
    region: np.ndarray
    from_start: bool


class SearchMemory:
    """Lets a planner asked again for the same start and goal say "still no path" quickly.

    A robot waiting for people to clear its way plans again every second from where it
    stands; each plan without a path searched every cell it could reach. Given one of these,
    :meth:`Planner.plan` keeps what a plan without a path found closed, and the next plan to
    the same goal cell, from a start on the closed start's side (or off the closed goal's),
    first asks whether that side can have opened (:func:`~cyborg.nav.search.still_closed`):
    only then does it search. The answer is the one a search would give.
    """

    def __init__(self) -> None:
        self.closed: ClosedSide | None = None
        self.searches = 0
        """Plans that searched (not answered from what was kept)."""


class Planner:
    """Plans paths on one map for one robot shape.

    Building it rasterises ``arnl_map`` at ``settings.resolution`` and computes the clearance
    and cost grids (default settings: :class:`PlannerSettings`); MapError if the map is too
    large for the grid caps (:mod:`cyborg.nav.map_limits`).
    """

    def __init__(self, arnl_map: ArnlMap, footprint: Footprint = PIONEER_LX,
                 settings: PlannerSettings | None = None) -> None:
        self.map = arnl_map
        self.footprint = footprint
        self.settings = settings or PlannerSettings()
        self.grid = MapGrid.from_map(arnl_map, self.settings.resolution)
        self.lethal = footprint.circumscribed_radius + self.settings.padding
        self.tight = footprint.inscribed_radius
        self.wall_clearance = self.grid.clearance(self.grid.walls)
        self.clearance = self.grid.clearance()
        self.cost = self._cost(self.clearance)
        self._opened = 2.0 + 2.0 * self.settings.cost_weight  # a tight cell near start, goal
        self._lock = threading.Lock()  # plans from any thread share the scratch grids
        self._grids: tuple[np.ndarray, np.ndarray] | None = None
        self._landmarks = NO_LANDMARKS
        self._plans = 0

    # ------------------------------------------------------------------ checks
    def check(self, pose: Pose2D, role: str = "goal") -> tuple[str, str] | None:
        """``(code, reason)`` if the robot cannot stand at ``pose``, else None.

        A pose that is not finite (NaN or infinite, from a service request or the command
        line) is off the map: it has no cell, and a heading of NaN could never be reached.
        """
        grid = self.grid
        occupied = START_OCCUPIED if role == "start" else GOAL_OCCUPIED
        where = f"{role} ({pose.x:.2f}, {pose.y:.2f})"
        if not all(math.isfinite(value) for value in (pose.x, pose.y, pose.theta)):
            return ((OUTSIDE_MAP if role == "start" else GOAL_OCCUPIED),
                    f"{where} heading {pose.theta:.2f} is not a finite pose")
        row, column = grid.cell(pose.x, pose.y)
        if not grid.inside(row, column):
            return (OUTSIDE_MAP if role == "start" else GOAL_OCCUPIED), f"{where} is off the map"
        if grid.forbidden[row, column]:
            return occupied, f"{where} is inside a forbidden area or on a forbidden line"
        if self.wall_clearance[row, column] < self.tight:
            return occupied, (f"{where} is inside a wall (clearance "
                              f"{self.wall_clearance[row, column]:.2f} m, the robot needs "
                              f"{self.tight:.2f} m)")
        return None

    # ------------------------------------------------------------------ planning
    def plan(self, start: Pose2D, goal: Pose2D, *, use_heading: bool = False,
             obstacles: np.ndarray | None = None, discs: np.ndarray | None = None,
             memory: SearchMemory | None = None) -> PlanResult:
        """Plan from ``start`` to ``goal``.

        ``obstacles``: extra (N, 2) points (sensed ones), blocked like walls; ``discs``: (N, 3)
        temporary obstacles (centre x, y and keep-out radius, m), see the module; ``memory``
        keeps what a plan without a path found, for the next between the same cells.
        """
        began = time.perf_counter()
        problem = self.check(start, "start") or self.check(goal, "goal")
        if problem is not None:
            return PlanResult(None, *problem, planning_time=time.perf_counter() - began)
        with self._lock:
            clearance, cost = self._scratch()
            changed: list[Window] = []
            try:
                if obstacles is not None and len(obstacles):
                    self._around(obstacles, clearance, cost, changed)
                for pose in (start, goal):
                    self._open_escape(cost, clearance, pose, changed)
                if discs is not None and len(discs):
                    self.stamp_discs(clearance, cost, clear_of(
                        discs, [(start.x, start.y), (goal.x, goal.y)], self.lethal,
                        2 * self.grid.resolution), changed)
                return self._plan_on(clearance, cost, start, goal, use_heading, memory, began)
            finally:
                self._restore(changed)

    def _plan_on(self, clearance: np.ndarray, cost: np.ndarray, start: Pose2D, goal: Pose2D,
                 use_heading: bool, memory: SearchMemory | None, began: float) -> PlanResult:
        """:meth:`plan` on the grids made for it (obstacles, escapes and discs in them)."""
        _rows, columns = self.grid.shape
        start_cell = self.grid.cell(start.x, start.y)
        goal_cell = self.grid.cell(goal.x, goal.y)
        if goal_cell != start_cell and not np.isfinite(cost[goal_cell]):
            # what was sensed covers the goal: no search would reach it, however long
            return PlanResult(None, GOAL_OCCUPIED,
                              f"goal ({goal.x:.2f}, {goal.y:.2f}) is taken by an obstacle "
                              f"seen there", time.perf_counter() - began)
        self._plans += 1
        if self._plans == LANDMARKS_AFTER:
            self._landmarks = self._learn_landmarks(start_cell[0] * columns + start_cell[1])
        cells = self._search(cost, start_cell[0] * columns + start_cell[1],
                             goal_cell[0] * columns + goal_cell[1], memory)
        if len(cells) == 0:
            return PlanResult(None, NO_VALID_PATH,
                              f"no path from ({start.x:.2f}, {start.y:.2f}) to "
                              f"({goal.x:.2f}, {goal.y:.2f}): the goal is cut off",
                              time.perf_counter() - began)
        path = self._smooth(cells, clearance, start, goal)
        return PlanResult(Path(path, goal.theta if use_heading else None),
                          planning_time=time.perf_counter() - began)

    def _learn_landmarks(self, start: int) -> np.ndarray:
        """Costs to far-apart landmarks on the grid as cheap as any plan's can be.

        Every cell that clears the inscribed radius (the tightest a plan opens, near its start
        and goal) at the smaller of its cost and an opened cell's; the landmarks in the part
        of the map the flat cell ``start`` lies in (where the plans are); (cells, K) float32,
        K :data:`LANDMARKS`, fewer where they would take more than :data:`LANDMARK_BYTES`.
        """
        cells = self.cost.size
        count = min(LANDMARKS, LANDMARK_BYTES // (4 * cells))
        if count <= 0:
            return NO_LANDMARKS
        opened = np.where(self.clearance >= self.tight, self._opened, np.inf)
        cheapest = np.ascontiguousarray(np.fmin(self.cost, opened))
        return landmark_costs(cheapest, start, count)

    def _search(self, cost: np.ndarray, start: int, goal: int,
                memory: SearchMemory | None) -> np.ndarray:
        """:func:`~cyborg.nav.search.astar`'s cells, answered from ``memory`` where it can."""
        known = memory.closed if memory is not None else None
        if (known is not None and known.goal == goal and known.passable.shape == cost.shape
                and bool(np.isfinite(cost.flat[goal])) == bool(known.passable.flat[goal])
                # a start on the closed start's side (it reaches what that start reached),
                # or off the closed goal's side
                and bool(known.region.flat[start]) == known.from_start
                and still_closed(cost, known.passable, known.region,
                                 goal if known.from_start else start)):
            return np.zeros(0, np.int64)
        cells, region, side = search(cost, start, goal, self._landmarks)
        if memory is not None:
            memory.searches += 1
            memory.closed = None if len(cells) or not side else ClosedSide(
                goal, np.isfinite(cost), region.reshape(cost.shape), side == START_SIDE)
        return cells

    def passable_near(self, start: Pose2D, goal: Pose2D, obstacles: np.ndarray,
                      margin: float) -> bool:
        """Whether a path from ``start`` to a near ``goal`` passes ``obstacles`` close by.

        The search keeps to the box around the two poses grown by ``margin`` m, so it costs
        little whatever the map's size; a way that must leave the box is not found. This
        tells whether sensed obstacles (N x 2 points) close the way ahead, before a search of
        the whole map that would only fail after visiting every cell it can reach.
        """
        if self.check(start, "start") or self.check(goal, "goal"):
            return False
        grid = self.grid
        corners = np.array([(start.x, start.y), (goal.x, goal.y)])
        rows, columns = grid.cells_of(np.vstack([corners.min(axis=0) - margin,
                                                 corners.max(axis=0) + margin]))
        with self._lock:
            clearance, cost = self._scratch()
            changed: list[Window] = []
            try:
                if len(obstacles):
                    self._around(obstacles, clearance, cost, changed)
                for pose in (start, goal):
                    self._open_escape(cost, self.clearance, pose, changed)
                window = np.ascontiguousarray(cost[rows[0]:rows[1] + 1,
                                                   columns[0]:columns[1] + 1])
            finally:
                self._restore(changed)
        width = window.shape[1]
        (r0, c0), (r1, c1) = grid.cell(start.x, start.y), grid.cell(goal.x, goal.y)
        return len(astar(window, (r0 - rows[0]) * width + c0 - columns[0],
                         (r1 - rows[0]) * width + c1 - columns[0])) > 0

    def stamp_discs(self, clearance: np.ndarray, cost: np.ndarray, discs: np.ndarray,
                    changed: list[Window] | None = None) -> None:
        """Stamp (N, 3) discs into a clearance grid and its cost grid, in place.

        Around each disc a window of cells gets the smaller of its clearance and its distance
        to the disc's edge, and the larger of its cost and the cost that distance gives (the
        planner's lethal radius and ramp, as near a wall); cells outside the windows are left
        as they are, so a few discs cost a few thousand cells, whatever the map's size. A
        disc with a number that is not finite is left out. The windows join ``changed``.
        """
        grid, resolution = self.grid, self.grid.resolution
        rows, columns = grid.shape
        for x, y, keep_out in discs[np.isfinite(discs).all(axis=1)]:
            reach = keep_out + self.lethal + self.settings.cost_ramp
            if reach <= 0:
                continue
            row, column = grid.cell(x, y)
            span = math.ceil(reach / resolution) + 1
            r0, r1 = max(row - span, 0), min(row + span + 1, rows)
            c0, c1 = max(column - span, 0), min(column + span + 1, columns)
            if r0 >= r1 or c0 >= c1:
                continue
            if changed is not None:
                changed.append((slice(r0, r1), slice(c0, c1)))
            centres_y = grid.origin_y + (np.arange(r0, r1) + 0.5) * resolution
            centres_x = grid.origin_x + (np.arange(c0, c1) + 0.5) * resolution
            gap = np.hypot(centres_x[None, :] - x, centres_y[:, None] - y) - keep_out
            window = clearance[r0:r1, c0:c1]
            np.minimum(window, np.maximum(gap, 0.0).astype(window.dtype), out=window)
            np.maximum(cost[r0:r1, c0:c1], self._cost(np.maximum(gap, 0.0)),
                       out=cost[r0:r1, c0:c1])

    def _scratch(self) -> tuple[np.ndarray, np.ndarray]:
        """Grids a plan changes in windows and :meth:`_restore` sets back: the map's, copied.

        Copied once, not at every plan (two copies of the map's grids made a plan on the
        campus a millisecond dearer); the caller holds the lock.
        """
        if self._grids is None:
            self._grids = (self.clearance.copy(), self.cost.copy())
        return self._grids

    def _restore(self, changed: list[Window]) -> None:
        """Set the windows ``changed`` of the scratch grids back to the map's own."""
        if self._grids is not None:
            clearance, cost = self._grids
            for window in changed:
                clearance[window] = self.clearance[window]
                cost[window] = self.cost[window]

    def _around(self, obstacles: np.ndarray, clearance: np.ndarray, cost: np.ndarray,
                changed: list[Window]) -> None:
        """Add ``obstacles`` (N x 2 points, m) to the map's ``clearance`` and ``cost``, in place.

        The clearance to walls and points is the smaller of the two clearances, and points
        change the cost only within the lethal distance and the cost ramp of them: so only the
        window around the points is computed again (a distance transform of that window),
        not the whole map; it joins ``changed``.
        """
        grid = self.grid
        reach = math.ceil(max(self.lethal + self.settings.cost_ramp,
                              self.settings.smoothing_margin) / grid.resolution) + 1
        rows, columns = grid.cells_of(obstacles)
        r0, r1 = max(int(rows.min()) - reach, 0), min(int(rows.max()) + reach + 1, grid.shape[0])
        c0, c1 = (max(int(columns.min()) - reach, 0),
                  min(int(columns.max()) + reach + 1, grid.shape[1]))
        free = np.ones((r1 - r0, c1 - c0), bool)
        free[rows - r0, columns - c0] = False
        near = (ndimage.distance_transform_edt(free) * grid.resolution).astype(np.float32)
        changed.append((slice(r0, r1), slice(c0, c1)))
        window = np.minimum(clearance[r0:r1, c0:c1], near)
        clearance[r0:r1, c0:c1] = window
        cost[r0:r1, c0:c1] = self._cost(window)

    def _cost(self, clearance: np.ndarray) -> np.ndarray:
        ramp = self.settings.cost_ramp
        closeness = np.clip((self.lethal + ramp - clearance) / ramp, 0.0, 1.0)
        cost = 1.0 + self.settings.cost_weight * closeness ** 2
        return np.where(clearance >= self.lethal, cost, np.inf)

    def _open_escape(self, cost: np.ndarray, clearance: np.ndarray, pose: Pose2D,
                     changed: list[Window] | None = None) -> None:
        """Let the search use tight cells (clearing only the inscribed radius) near ``pose``.

        The window joins ``changed``, if given.
        """
        grid, radius = self.grid, self.settings.escape_radius
        reach = math.ceil(radius / grid.resolution)
        row, column = grid.cell(pose.x, pose.y)
        r0, r1 = max(row - reach, 0), min(row + reach + 1, grid.shape[0])
        c0, c1 = max(column - reach, 0), min(column + reach + 1, grid.shape[1])
        if changed is not None:
            changed.append((slice(r0, r1), slice(c0, c1)))
        rr, cc = np.mgrid[r0:r1, c0:c1]
        near = np.hypot(rr - row, cc - column) * grid.resolution <= radius
        window = clearance[r0:r1, c0:c1]
        tight = near & (window >= self.tight) & ~np.isfinite(cost[r0:r1, c0:c1])
        cost[r0:r1, c0:c1][tight] = self._opened

    def _smooth(self, cells: np.ndarray, clearance: np.ndarray, start: Pose2D,
                goal: Pose2D) -> np.ndarray:
        grid = self.grid
        columns = grid.shape[1]
        rows_, cols_ = cells // columns, cells % columns
        points = np.column_stack([grid.origin_x + (cols_ + 0.5) * grid.resolution,
                                  grid.origin_y + (rows_ + 0.5) * grid.resolution])
        points[0] = (start.x, start.y)
        points[-1] = (goal.x, goal.y)
        floors = clearance[rows_, cols_].astype(np.float64)
        if len(points) <= 2:
            return points
        kept = shortcut(points, floors, clearance, grid.origin_x, grid.origin_y,
                        grid.resolution, self.settings.smoothing_margin)
        smoothed: np.ndarray = points[kept]
        return smoothed
