"""Going to a goal, as ARNL's goto mode does: plan, follow, replan around obstacles, give up.

States are rosarnl's ``arnl_path_state`` strings (:class:`cyborg.interfaces.robot.PathState`).
A goal that cannot be planned ends at once in ``FAILED_PLAN``; while moving, an obstacle the
map does not know about (a box, a person) that blocks the path ahead triggers a replan that
treats the laser's returns as walls; when the distance still to go *along the path* has not
shrunk for ``stall_timeout`` seconds the goal ends in ``FAILED_MOVE``. Cancelling ends it in
``ABORTED_PATHPLAN`` and stops the robot.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numba import njit

from cyborg.interfaces.robot import PathState as PathState
from cyborg.nav.geometry import Pose2D
from cyborg.nav.planner import Planner, PlanResult
from cyborg.sim.follower import SLOW_CORRIDOR, FollowerSettings, PathFollower, front_ranges
from cyborg.sim.motion_check import Motion, Surroundings, safest_command


@dataclass(frozen=True)
class NavigatorSettings:
    """When to give up, replan and see obstacles: times in simulated seconds, lengths in m."""

    stall_timeout: float = 15.0  # seconds without progress along the path before giving up
    progress_step: float = 0.1  # metres of progress that count
    replan_interval: float = 2.0  # seconds between replans around a blocking obstacle
    blocked_patience: float = 2.0  # seconds stopped before an obstacle ahead before replanning
    look_ahead: float = 3.0  # metres of path checked against the laser
    sensed_range: float = 6.0  # laser returns within this distance become obstacles
    follower: FollowerSettings = field(default_factory=FollowerSettings)


class Navigator:
    """Drives to one goal at a time on a planner's map.

    ``settings`` default to :class:`NavigatorSettings`. :attr:`state` and :attr:`message` say
    how the goal goes; times (``now``) are simulated seconds.
    """

    def __init__(self, planner: Planner, settings: NavigatorSettings | None = None) -> None:
        self.planner = planner
        self.settings = settings or NavigatorSettings()
        self.state = PathState.NOT_INITIALIZED
        self.message = ""
        self.goal: Pose2D | None = None
        self.use_heading = False
        self.follower: PathFollower | None = None
        self.remaining = math.inf
        self.replans = 0
        self._best = math.inf
        self._progress_at = 0.0
        self._replanned_at = -math.inf
        self._blocked_since: float | None = None

    def go_to(self, start: Pose2D, goal: Pose2D, use_heading: bool, now: float) -> PlanResult:
        """Plan and start moving; the result says whether a path was found."""
        self.goal, self.use_heading = goal, use_heading
        self.state = PathState.PLANNING_PATH
        result = self.planner.plan(start, goal, use_heading=use_heading)
        if result.path is None:
            self.state, self.message, self.follower = PathState.FAILED_PLAN, result.reason, None
            self.remaining = math.inf
            return result
        self.follower = PathFollower(result.path, use_heading, self.settings.follower)
        self.state, self.message = PathState.MOVING_TO_GOAL, ""
        self.remaining = self._best = result.length
        self._progress_at, self.replans = now, 0
        return result

    def cancel(self) -> None:
        """Drop the goal; one still under way ends ``ABORTED_PATHPLAN`` ("cancelled")."""
        if not self.state.finished:
            self.state, self.message = PathState.ABORTED_PATHPLAN, "cancelled"
        self.follower = None

    def update(self, now: float, pose: Pose2D, ranges: np.ndarray, angles: np.ndarray,
               hits: np.ndarray, motion: Motion | None = None,
               period: float = 0.1) -> tuple[float, float]:
        """Speed (m/s) and turn rate (rad/s) for the next ``period`` seconds.

        ``ranges`` and ``angles`` are the latest scan's, ``hits`` its returns as map points;
        ``motion``: how the robot moves now (its odometry). With ``motion``, a command whose
        motion until standstill would touch a wall or a return is replaced by a gentler one
        (:func:`cyborg.sim.motion_check.safest_command`). Zero unless moving to a goal.
        """
        if self.state is not PathState.MOVING_TO_GOAL or self.follower is None:
            return 0.0, 0.0
        slow, stop = front_ranges(ranges, angles,
                                  (SLOW_CORRIDOR, self.planner.footprint.width / 2))
        command = self.follower.update(pose, slow, stop)
        self.remaining = command.remaining
        if command.arrived:
            self.state, self.message, self.follower = PathState.REACHED_GOAL, "", None
            return 0.0, 0.0
        if command.remaining < self._best - self.settings.progress_step:
            self._best, self._progress_at = command.remaining, now
        elif now - self._progress_at > self.settings.stall_timeout:
            self.state = PathState.FAILED_MOVE
            self.message = (f"no progress along the path for {self.settings.stall_timeout:g} s "
                            f"({command.remaining:.2f} m still to go)")
            self.follower = None
            return 0.0, 0.0
        if not command.blocked:
            self._blocked_since = None
        elif self._blocked_since is None:
            self._blocked_since = now
        stuck = (self._blocked_since is not None
                 and now - self._blocked_since >= self.settings.blocked_patience)
        if (now - self._replanned_at >= self.settings.replan_interval
                and (stuck or self._path_blocked(pose, hits))):
            self._replan(now, pose, hits)
        if motion is None:
            return command.speed, command.turn_rate
        grid = self.planner.grid
        around = Surroundings(self.planner.wall_clearance, (grid.origin_x, grid.origin_y),
                              grid.resolution, hits)
        return safest_command(pose.x, pose.y, pose.theta, motion,
                              (command.speed, command.turn_rate), period,
                              self.planner.footprint, around)

    def _path_blocked(self, pose: Pose2D, hits: np.ndarray) -> bool:
        assert self.follower is not None
        path = self.follower.path
        along, _gap = path.project(pose.x, pose.y)
        ahead = path.sample(along + 0.3, along + self.settings.look_ahead, 0.1)
        if len(ahead) == 0 or len(hits) == 0:
            return False
        return bool(closest_gap(hits, ahead) < self.planner.footprint.inscribed_radius + 0.05)

    def _replan(self, now: float, pose: Pose2D, hits: np.ndarray) -> None:
        assert self.goal is not None
        self._replanned_at = now
        near = hits[np.hypot(hits[:, 0] - pose.x, hits[:, 1] - pose.y)
                    < self.settings.sensed_range]
        result = self.planner.plan(pose, self.goal, use_heading=self.use_heading, obstacles=near)
        if result.path is not None:  # a detour may be longer: progress counts from here on,
            self.replans += 1           # but the stall clock keeps running
            self.follower = PathFollower(result.path, self.use_heading, self.settings.follower)
            self._best = result.length


@njit(cache=True)
def closest_gap(points: np.ndarray, others: np.ndarray) -> float:  # pragma: no cover - jit
    """The smallest distance between a point of ``points`` and one of ``others``."""
    best = np.inf
    for i in range(points.shape[0]):
        for j in range(others.shape[0]):
            gap = (points[i, 0] - others[j, 0]) ** 2 + (points[i, 1] - others[j, 1]) ** 2
            if gap < best:
                best = gap
    return float(np.sqrt(best))
