"""Robots that meet head-on settle it: one makes way for the other, by priority.

Two simulated robots that meet in a doorway or a narrow corridor, each on the other's way,
would wait for each other until both give up (each navigator sees the other as an obstacle
that no plan passes), and try again, and meet again. A fleet (:mod:`cyborg.sim.fleet`) asks
:class:`WayGiving` at each sensor step to find such *standoffs* and settle them, as people do
at a door:

* **Standoff.** Two robots, each with a goal, have stood for :data:`STANDOFF` seconds, and
  each lies on the way the other means to drive (its next :data:`AHEAD` metres, closer than
  :data:`ON_THE_WAY`). A robot that stands with a goal while one without a goal, or one that
  makes way itself, stands on its way is not a standoff: that one moves on by itself.
* **Priority.** The robot that came first in the fleet (robot 1 before robot 2) keeps its way;
  the other makes way: it drives a short path to the nearest place beside the first's way
  (:func:`place_aside`: reachable, its centre :data:`BESIDE` metres from that way and the
  robot, within :data:`SEARCH` metres) and stands there
  (:meth:`~cyborg.sim.navigator.Navigator.make_way`; its path state says it waits). When it
  has no such place, the first one makes way instead; when neither has, they wait as before.
* **On again.** The one that made way plans to its goal again (:meth:`~cyborg.sim.
  navigator.Navigator.resume`) once the other has no goal any more, or no longer lies on its
  way, or after :data:`GIVE_UP` seconds; or when it has stood :data:`STUCK` seconds short of
  its place (it cannot get there): then the next time the two meet, the other makes way.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numba import njit

from cyborg.nav.geometry import Pose2D
from cyborg.nav.planner import Planner
from cyborg.sim.bodies import outline_points
from cyborg.sim.navigator import PathState
from cyborg.sim.simulator import Simulator

STANDOFF = 3.0
"""Seconds two robots stand, each on the other's way, before one makes way."""
STILL = 0.05
"""Metres per second under which a robot counts as standing."""
AHEAD = 6.0
"""Metres of a robot's way ahead within which another robot stands in its way."""
ON_THE_WAY = 1.0
"""Metres from a way within which a robot's centre is on it (two bodies side by side)."""
BESIDE = 1.1
"""Metres a robot making way keeps its centre from the other's way and from the other."""
SEARCH = 6.0
"""Metres around a robot within which it looks for a place to make way."""
GIVE_UP = 40.0
"""Seconds after which a robot making way goes on whatever the other does."""
STUCK = 5.0
"""Seconds a robot making way may stand short of its place before it goes on, and the other
makes way the next time they meet."""


@dataclass
class Yielding:
    """A robot making way: for which robot, since when (simulated seconds)."""

    to: int
    since: float


class WayGiving:
    """Finds standoffs among ``count`` robots and settles them; see the module doc."""

    def __init__(self, count: int) -> None:
        self._still_since: list[float | None] = [None] * count
        self.yielding: dict[int, Yielding] = {}
        """The robots making way now, by index."""
        self.settled = 0
        """Standoffs settled so far."""
        self._first_gives: set[frozenset[int]] = set()  # pairs whose first makes way next

    def step(self, robots: Sequence[Simulator], now: float) -> None:
        """Look at the robots as they are at ``now``: settle standoffs, send those aside on."""
        for index, sim in enumerate(robots):
            if abs(sim.base.speed) >= STILL or abs(sim.base.turn_rate) >= STILL:
                self._still_since[index] = None
            elif self._still_since[index] is None:
                self._still_since[index] = now
        ways = [sim.way_ahead() for sim in robots]
        self._send_on(robots, ways, now)
        for first in range(len(robots)):
            for second in range(first + 1, len(robots)):
                if self._standoff(robots, ways, first, second, now):
                    self._settle(robots, ways, first, second, now)

    def _active(self, sim: Simulator) -> bool:
        navigator = sim.navigator
        return (navigator.state in (PathState.MOVING_TO_GOAL, PathState.WAITING_FOR_PATH)
                and not navigator.making_way)

    def _standoff(self, robots: Sequence[Simulator], ways: list[np.ndarray], first: int,
                  second: int, now: float) -> bool:
        """Whether ``first`` and ``second`` stand, each on the other's way, long enough."""
        for index in (first, second):
            since = self._still_since[index]
            if since is None or now - since < STANDOFF or not self._active(robots[index]):
                return False
            if robots[index].map is not robots[first].map:
                return False
        return (on_way(ways[first], robots[second].pose, AHEAD)
                and on_way(ways[second], robots[first].pose, AHEAD))

    def _settle(self, robots: Sequence[Simulator], ways: list[np.ndarray], first: int,
                second: int, now: float) -> None:
        """The lower in priority (``second``) makes way; if it cannot, ``first`` does.

        The other way round when the second, making way for the first, got stuck last time.
        """
        order = ((second, first), (first, second))
        if frozenset((first, second)) in self._first_gives:
            order = order[::-1]
        for giver, taker in order:
            sim, other = robots[giver], robots[taker]
            blockers = outline_points(other.outline, 0.1)
            place = place_aside(sim.planner, sim.pose, ways[taker], other.pose)
            if place is None:
                continue
            result = sim.planner.plan(sim.pose, place, obstacles=blockers)
            if result.path is None:
                continue
            sim.navigator.make_way(result.path, now, f"making way for robot {taker + 1}")
            self.yielding[giver] = Yielding(taker, now)
            self.settled += 1
            return

    def _send_on(self, robots: Sequence[Simulator], ways: list[np.ndarray],
                 now: float) -> None:
        """Robots done making way plan to their goals again."""
        for giver, yielding in list(self.yielding.items()):
            sim, other = robots[giver], robots[yielding.to]
            if not sim.navigator.making_way:
                del self.yielding[giver]  # a new goal, a cancel: done
                continue
            passed = (not self._active(other)
                      or not on_way(ways[yielding.to], sim.pose, math.inf))
            still = self._still_since[giver]
            stuck = (sim.navigator.stepping_aside and still is not None
                     and now - max(still, yielding.since) >= STUCK)
            if passed or stuck or now - yielding.since >= GIVE_UP:
                del self.yielding[giver]
                self._still_since[giver] = None  # a standoff again only after STANDOFF s
                if stuck:  # it cannot get out of the way: the other makes way next time
                    self._first_gives ^= {frozenset((giver, yielding.to))}
                sim.navigator.resume(now, sim.pose)


def on_way(way: np.ndarray, pose: Pose2D, reach: float) -> bool:
    """Whether ``pose`` lies on ``way`` ((N, 2) points) within its first ``reach`` metres."""
    if len(way) == 0:
        return False
    along = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(way, axis=0).T))])
    near = way[along <= reach]
    return bool(np.min(np.hypot(near[:, 0] - pose.x, near[:, 1] - pose.y)) < ON_THE_WAY)


def place_aside(planner: Planner, start: Pose2D, way: np.ndarray,
                other: Pose2D) -> Pose2D | None:
    """The nearest place a robot at ``start`` reaches that lies beside ``way``; or None.

    Beside: the robot's centre :data:`BESIDE` m from every point of the way (the other robot's,
    (N, 2)) and from the other robot at ``other``, in a cell the planner lets it stand on.
    Nearest by steps over such cells from ``start`` (near it, cells clearing the robot's
    inscribed radius too, as the planner's escape), round the other robot by both bodies'
    circumscribed radii, or as far as it is now if nearer, never closer (a robot in a doorway
    with the other at its far side makes way back, not past it), within :data:`SEARCH` m.
    """
    grid = planner.grid
    row, column = grid.cell(start.x, start.y)
    reach = math.ceil(SEARCH / grid.resolution)
    r0, r1 = max(row - reach, 0), min(row + reach + 1, grid.shape[0])
    c0, c1 = max(column - reach, 0), min(column + reach + 1, grid.shape[1])
    if not (r0 <= row < r1 and c0 <= column < c1):
        return None
    xs = grid.origin_x + (np.arange(c0, c1) + 0.5) * grid.resolution
    ys = grid.origin_y + (np.arange(r0, r1) + 0.5) * grid.resolution
    clearance = planner.clearance[r0:r1, c0:c1]
    escape = ((xs[None, :] - start.x) ** 2 + (ys[:, None] - start.y) ** 2
              <= planner.settings.escape_radius ** 2)
    passable = (clearance >= planner.lethal) | (escape & (clearance >= planner.tight))
    keep = min(2 * planner.lethal, math.hypot(start.x - other.x, start.y - other.y))
    passable &= ((xs[None, :] - other.x) ** 2 + (ys[:, None] - other.y) ** 2
                 >= keep ** 2)  # never closer to the other, nor past it however it turns
    points = np.vstack([way, [(other.x, other.y)]]) if len(way) else np.array(
        [(other.x, other.y)])
    beside = np.ones(passable.shape, bool)
    for x, y in points:
        beside &= (xs[None, :] - x) ** 2 + (ys[:, None] - y) ** 2 >= BESIDE ** 2
    found = nearest_cell(passable, beside & passable, row - r0, column - c0)
    if found < 0:
        return None
    found_row, found_column = divmod(found, c1 - c0)
    return Pose2D(float(xs[found_column]), float(ys[found_row]), start.theta)


@njit(cache=True)
def nearest_cell(passable: np.ndarray, wanted: np.ndarray, row: int,
                 column: int) -> int:  # pragma: no cover - jit
    """The flat index of the ``wanted`` cell fewest 8-connected steps from ``(row, column)``.

    Steps go over ``passable`` cells only (the start may be any); -1 when none is reached.
    """
    rows, columns = passable.shape
    seen = np.zeros(rows * columns, np.bool_)
    queue = np.empty(rows * columns, np.int64)
    start = row * columns + column
    queue[0], seen[start] = start, True
    head, tail = 0, 1
    while head < tail:
        current = int(queue[head])
        head += 1
        r, c = current // columns, current % columns
        if wanted[r, c]:
            return current
        for dr in range(-1, 2):
            for dc in range(-1, 2):
                nr, nc = r + dr, c + dc
                if (dr == 0 and dc == 0) or nr < 0 or nr >= rows or nc < 0 or nc >= columns:
                    continue
                index = nr * columns + nc
                if not seen[index] and passable[nr, nc]:
                    seen[index] = True
                    queue[tail] = index
                    tail += 1
    return -1
