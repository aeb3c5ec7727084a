"""Going to a goal, as ARNL's goto mode does: plan, follow, replan around obstacles, give up.

States are rosarnl's ``arnl_path_state`` strings (:class:`cyborg.interfaces.robot.PathState`).
A goal that cannot be planned ends at once in ``FAILED_PLAN``; while moving, an obstacle the
map does not know about (a box, a person) that blocks the path ahead for ``blocked_persistence``
seconds (someone crossing it does not) triggers a replan that treats the laser's returns as
walls, once a cheap search near the path ahead finds a way past them (else the robot waits in
front, and plans on the whole map once stopped for ``blocked_patience`` seconds); when the
distance still to go *along the path* has not shrunk for ``stall_timeout`` seconds the goal
ends in ``FAILED_MOVE``. Cancelling ends it in ``ABORTED_PATHPLAN`` and stops the robot.

Objects seen lately (:attr:`Navigator.obstacles`, fed from the tracker's ``objects``) are
temporary obstacles (:mod:`cyborg.nav.temporary_obstacles`): those within ``obstacle_range``
are discs the planner keeps clear of. When one comes onto the path ahead (deeper than
``blocked_hysteresis`` into its lethal zone) the navigator replans around it; when no way
passes them, the robot stops and the state is ``WAITING_FOR_PATH``: it plans again every
``wait_retry`` seconds until a way opens (the object moved on, or was forgotten) and goes on
``MOVING_TO_GOAL``, its stall clock started afresh. Waiting is not stalling: only a wait longer
than ``wait_timeout`` ends the goal (``FAILED_MOVE``). A goal given while the only way is
blocked so starts out waiting.

**Making way.** Two robots that meet head-on in a doorway wait for each other for good; the
fleet (:mod:`cyborg.sim.giving_way`) settles it by having one of them :meth:`~Navigator.
make_way`: it drives a short path to a place beside the other's way and stands there, its goal
kept and its state ``WAITING_FOR_PATH`` (waiting for the other to pass), until told to
:meth:`~Navigator.resume`, when it plans to its goal again.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from cyborg.interfaces.robot import PathState as PathState
from cyborg.nav.geometry import Path, Pose2D, normalize_angle
from cyborg.nav.planner import Planner, PlanResult, SearchMemory
from cyborg.nav.temporary_obstacles import (
    ObstacleSettings,
    TemporaryObstacles,
    clear_of,
    path_blocked,
)
from cyborg.sim.follower import (
    SLOW_CORRIDOR,
    FollowerSettings,
    PathFollower,
    ahead_of_the_map,
    any_within,
)
from cyborg.sim.motion_check import Motion, Surroundings, safest_command

MAPPED = 0.15
"""Metres from a mapped wall within which a laser return is that wall (see
:meth:`Navigator._unmapped`)."""


@dataclass(frozen=True)
class NavigatorSettings:
    """When to give up, replan and see obstacles: times in simulated seconds, lengths in m."""

    stall_timeout: float = 15.0  # seconds without progress along the path before giving up
    progress_step: float = 0.1  # metres of progress that count
    replan_interval: float = 2.0  # seconds between replans around a blocking obstacle
    blocked_patience: float = 2.0  # seconds stopped before an obstacle ahead before replanning
    look_ahead: float = 3.0  # metres of path checked against the laser
    blocked_persistence: float = 1.0  # seconds the laser must see the path blocked to replan
    detour_margin: float = 3.0  # metres around the way ahead searched for a way past (cheap)
    sensed_range: float = 6.0  # laser returns within this distance become obstacles
    follower: FollowerSettings = field(default_factory=FollowerSettings)
    obstacles: ObstacleSettings = field(default_factory=ObstacleSettings)
    obstacle_range: float = 6.0  # temporary obstacles within this distance count
    blocked_hysteresis: float = 0.1  # metres into a disc's lethal zone that block the path
    obstacle_replan_interval: float = 0.5  # seconds between replans around temporary obstacles
    wait_retry: float = 1.0  # seconds between plans while waiting for a way past them
    wait_timeout: float = 60.0  # seconds of waiting before giving up


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
        self.waits = 0
        self.obstacles = TemporaryObstacles(self.settings.obstacles)
        self._waiting_since = 0.0
        self._tried_at = -math.inf
        self._obstacle_replan_at = -math.inf
        self._best = math.inf
        self._progress_at = 0.0
        self._replanned_at = -math.inf
        self._blocked_since: float | None = None
        self._ahead_since: float | None = None  # since when the laser sees the path blocked
        self._blocked_way: Path | None = None  # the way a wait is for
        self._aside: PathFollower | None = None  # making way: the path to the place aside
        self._backing: bool | None = None  # whether it backs to the place aside
        self._memory = SearchMemory()  # what a plan past obstacles without a path found
        self.making_way = False
        """Whether the robot makes way for another (see :meth:`make_way`)."""

    def go_to(self, start: Pose2D, goal: Pose2D, use_heading: bool, now: float) -> PlanResult:
        """Plan and start moving; the result says whether a path was found."""
        self.goal, self.use_heading = goal, use_heading
        self.state, self.follower, self.replans, self.waits = PathState.PLANNING_PATH, None, 0, 0
        self.making_way, self._aside = False, None
        discs = self._discs(now, start)
        result = self.planner.plan(start, goal, use_heading=use_heading, discs=discs)
        if result.path is None and len(discs):
            unblocked = self.planner.plan(start, goal, use_heading=use_heading)
            if unblocked.path is not None:  # only the objects are in the way: wait for them
                self.remaining = unblocked.length
                self._start_waiting(now, len(discs), unblocked.path)
                return unblocked
        if result.path is None:
            self.state, self.message = PathState.FAILED_PLAN, result.reason
            self.remaining = math.inf
            return result
        self._follow(result, now)
        return result

    def _follow(self, result: PlanResult, now: float) -> None:
        """Start following a fresh plan: moving, progress counted from here."""
        assert result.path is not None
        self.follower = PathFollower(result.path, self.use_heading, self.settings.follower)
        self.state, self.message = PathState.MOVING_TO_GOAL, ""
        self.remaining = self._best = result.length
        self._progress_at, self._blocked_since = now, None

    def way_ahead(self, pose: Pose2D, reach: float, step: float = 0.2) -> np.ndarray:
        """Points every ``step`` m along the next ``reach`` m of the way the robot means to take.

        (N, 2), from the point nearest to ``pose`` on: the path it follows, or while it waits
        for objects to make way, the path they block; empty when it has no goal. What people
        keep off (:mod:`cyborg.sim.people`).
        """
        way = (self.follower.path if self.state is PathState.MOVING_TO_GOAL
               and self.follower is not None else
               self._blocked_way if self.state is PathState.WAITING_FOR_PATH else None)
        if way is None:
            return np.zeros((0, 2))
        along, _gap = way.project(pose.x, pose.y)
        return way.sample(along, along + reach, step)

    @property
    def stepping_aside(self) -> bool:
        """Whether the robot makes way and has not reached the place aside yet."""
        return self.making_way and self._aside is not None

    @property
    def waiting(self) -> bool:
        """Whether the robot stands waiting for a way past temporary obstacles."""
        return self.state is PathState.WAITING_FOR_PATH

    def cancel(self) -> None:
        """Drop the goal; one still under way ends ``ABORTED_PATHPLAN`` ("cancelled")."""
        if not self.state.finished:
            self.state, self.message = PathState.ABORTED_PATHPLAN, "cancelled"
        self.follower = None
        self.making_way, self._aside = False, None

    def make_way(self, aside: Path, now: float, why: str) -> None:
        """Drive ``aside`` (a short path off another robot's way) and stand at its end.

        The goal is kept; the state is ``WAITING_FOR_PATH`` with ``why`` as the message (a
        wait for the other to pass, not a stall) until :meth:`resume`.
        """
        self.making_way, self._aside = True, PathFollower(aside, False, self.settings.follower)
        self._backing = None  # decided at the first step aside
        self.state, self.message = PathState.WAITING_FOR_PATH, why
        self._waiting_since = self._tried_at = now
        self.follower = None

    def resume(self, now: float, pose: Pose2D) -> None:
        """Done making way: plan from ``pose`` to the goal again and go on (or wait there)."""
        if not self.making_way or self.goal is None:
            return
        waits = self.waits
        self.go_to(pose, self.goal, self.use_heading, now)
        self.waits = waits + 1

    def update(self, now: float, pose: Pose2D, ranges: np.ndarray, angles: np.ndarray,
               hits: np.ndarray, motion: Motion | None = None,
               period: float = 0.1, mount: float = 0.0) -> tuple[float, float]:
        """Speed (m/s) and turn rate (rad/s) for the next ``period`` seconds.

        ``ranges`` and ``angles`` are the latest scan's (from a scanner ``mount`` m ahead of
        the robot's centre), ``hits`` its returns as map points; ``motion``: how the robot
        moves now (its odometry). With ``motion``, a command whose motion until standstill
        would touch a wall or a return is replaced by a gentler one
        (:func:`cyborg.sim.motion_check.safest_command`). Zero unless moving to a goal;
        braking while waiting for a way past temporary obstacles.
        """
        if self.making_way:
            return self._step_aside(pose, self._front(pose, ranges, angles, mount), hits,
                                    motion, period)
        if self.state is PathState.WAITING_FOR_PATH:
            return self._wait(now, pose, hits, motion, period)
        if self.state is not PathState.MOVING_TO_GOAL or self.follower is None:
            return 0.0, 0.0
        command = self.follower.update(pose, *self._front(pose, ranges, angles, mount))
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
        discs = self._discs(now, pose)
        if (len(discs) and now - self._obstacle_replan_at
                >= self.settings.obstacle_replan_interval and self._discs_block(pose, discs)):
            self._obstacle_replan_at = now
            self._replan(now, pose, hits, discs)
        elif (now - self._replanned_at >= self.settings.replan_interval
                and (stuck or self._blocked_for(now, pose, hits)
                     >= self.settings.blocked_persistence)):
            if stuck or self._way_ahead_open(pose, hits):
                self._replan(now, pose, hits, discs)
            else:  # closed near by: asked again after the interval, if still blocked
                self._replanned_at, self._ahead_since = now, None
        if self.waiting:  # the replan found no way past the objects
            return self._checked(pose, (0.0, 0.0), hits, motion, period)
        return self._checked(pose, (command.speed, command.turn_rate), hits, motion, period)

    def _front(self, pose: Pose2D, ranges: np.ndarray, angles: np.ndarray,
               mount: float) -> tuple[float, float]:
        """The nearest return ahead in the corridor that slows and in the one that stops it.

        The robot slows for whatever is near ahead, and stops only for what the map does not
        know (returns further than :data:`MAPPED` m from its walls): the path keeps clear of
        the walls and the motion check keeps the robot off them, while a wall corner ahead of
        a robot whose path turns away round it would stop it for good.
        """
        grid = self.planner.grid
        slow, stop = ahead_of_the_map(
            np.ascontiguousarray(ranges, dtype=np.float64),
            np.ascontiguousarray(angles, dtype=np.float64),
            pose.x + mount * math.cos(pose.theta), pose.y + mount * math.sin(pose.theta),
            pose.theta, self.planner.wall_clearance, grid.origin_x, grid.origin_y,
            grid.resolution, MAPPED, SLOW_CORRIDOR, self.planner.footprint.width / 2)
        return slow, stop

    def _step_aside(self, pose: Pose2D, front: tuple[float, float], hits: np.ndarray,
                    motion: Motion | None, period: float) -> tuple[float, float]:
        """Drive to the place aside while making way, then stand there (``front``: ranges).

        A place behind the robot (its way there leaving more than a right angle off its
        heading) it backs to, slowly, as one backs out of a doorway rather than turn in it:
        following the way as if it faced backwards, with no laser behind (the motion check
        keeps it off what it knows is there).
        """
        if self._aside is None:
            return self._checked(pose, (0.0, 0.0), hits, motion, period)
        path = self._aside.path
        if self._backing is None:
            x, y = path.point_at(min(path.length, self.settings.follower.lookahead))
            self._backing = abs(normalize_angle(math.atan2(y - pose.y, x - pose.x)
                                                - pose.theta)) > math.pi / 2
        if self._backing:
            command = self._aside.update(Pose2D(pose.x, pose.y, pose.theta + math.pi), math.inf)
            speed = -min(command.speed, self.settings.follower.slow_speed)
        else:
            command = self._aside.update(pose, *front)
            speed = command.speed
        if command.arrived:
            self._aside = None
            return self._checked(pose, (0.0, 0.0), hits, motion, period)
        return self._checked(pose, (speed, command.turn_rate), hits, motion, period)

    def _checked(self, pose: Pose2D, command: tuple[float, float], hits: np.ndarray,
                 motion: Motion | None, period: float) -> tuple[float, float]:
        """``command``, or a gentler one if braking after it would touch what is known."""
        if motion is None:
            return command
        grid = self.planner.grid
        around = Surroundings(self.planner.wall_clearance, (grid.origin_x, grid.origin_y),
                              grid.resolution, hits)
        return safest_command(pose.x, pose.y, pose.theta, motion, command, period,
                              self.planner.footprint, around)

    # ------------------------------------------------------------------ temporary obstacles
    def _discs(self, now: float, pose: Pose2D) -> np.ndarray:
        """The temporary obstacles within ``obstacle_range`` of ``pose``, as discs."""
        return self.obstacles.discs(now, near=(pose.x, pose.y),
                                    within=self.settings.obstacle_range)

    def _discs_block(self, pose: Pose2D, discs: np.ndarray) -> bool:
        """Whether the discs (shrunk as the planner shrinks them) lie on the path ahead."""
        assert self.follower is not None and self.goal is not None
        path = self.follower.path
        along, _gap = path.project(pose.x, pose.y)
        ahead = path.sample(along, along + self.settings.obstacle_range, 0.1)
        shrunk = clear_of(discs, [(pose.x, pose.y), (self.goal.x, self.goal.y)],
                          self.planner.lethal, 2 * self.planner.grid.resolution)
        return path_blocked(shrunk, ahead, self.planner.lethal,
                            self.settings.blocked_hysteresis)

    def _start_waiting(self, now: float, count: int, way: Path | None) -> None:
        self.state, self.waits = PathState.WAITING_FOR_PATH, self.waits + 1
        self._blocked_way = way
        self.message = (f"waiting: {count} object{'s' if count != 1 else ''} seen lately "
                        f"block every way to the goal")
        self._waiting_since = self._tried_at = now

    def _wait(self, now: float, pose: Pose2D, hits: np.ndarray, motion: Motion | None,
              period: float) -> tuple[float, float]:
        """Stand, and plan again every ``wait_retry`` s until a way opens or time is up."""
        settings = self.settings
        if now - self._waiting_since > settings.wait_timeout:
            self.state, self.follower = PathState.FAILED_MOVE, None
            self.message = (f"waited {settings.wait_timeout:g} s for the objects in the way "
                            f"to move")
            return 0.0, 0.0
        if now - self._tried_at >= settings.wait_retry:
            self._tried_at = now
            result = self._plan_around(pose, hits, self._discs(now, pose))
            if result.path is not None:
                self._follow(result, now)
        return self._checked(pose, (0.0, 0.0), hits, motion, period)

    def _unmapped(self, pose: Pose2D, hits: np.ndarray) -> np.ndarray:
        """The returns within ``sensed_range`` of ``pose`` that the map does not explain.

        A return on a mapped wall (within :data:`MAPPED` m of it) is that wall, which the
        planner keeps clear of already; taken again as a point, sampled a cell off the
        planner's own, it would close a passage that the robot only just clears (AMROffice's
        doors) to every plan past what it does not know.
        """
        near = hits[np.hypot(hits[:, 0] - pose.x, hits[:, 1] - pose.y)
                    < self.settings.sensed_range]
        if len(near) == 0:
            return near
        rows, columns = self.planner.grid.cells_of(near)
        unmapped: np.ndarray = near[self.planner.wall_clearance[rows, columns] > MAPPED]
        return unmapped

    def _plan_around(self, pose: Pose2D, hits: np.ndarray, discs: np.ndarray) -> PlanResult:
        """A plan from ``pose`` past the laser's near returns the map lacks and the discs."""
        assert self.goal is not None
        near = self._unmapped(pose, hits)
        return self.planner.plan(pose, self.goal, use_heading=self.use_heading, obstacles=near,
                                 discs=discs, memory=self._memory)

    def _way_ahead_open(self, pose: Pose2D, hits: np.ndarray) -> bool:
        """Whether a way past what the laser sees on the path ahead opens near the robot.

        Searched in a box around the robot and the path a little beyond the part checked
        (``look_ahead``), with ``detour_margin`` m to spare: cheap. When someone stands
        across a corridor there is none, and a search of the whole map would visit every cell
        it reaches before saying so; the robot waits in front instead, and searches the whole
        map once it has stood blocked for ``blocked_patience`` s (a way round elsewhere).
        """
        assert self.follower is not None
        path, settings = self.follower.path, self.settings
        along, _gap = path.project(pose.x, pose.y)
        beyond = Pose2D(*path.point_at(along + settings.look_ahead + 1.0))
        return self.planner.passable_near(pose, beyond, self._unmapped(pose, hits),
                                          settings.detour_margin)

    def _blocked_for(self, now: float, pose: Pose2D, hits: np.ndarray) -> float:
        """Seconds the laser has seen the path ahead blocked without a break (0: clear now).

        Someone crossing the path or stepping out of the way clears it within a second: only
        what stays in the way is worth a plan around it.
        """
        if not self._path_blocked(pose, hits):
            self._ahead_since = None
            return 0.0
        if self._ahead_since is None:
            self._ahead_since = now
        return now - self._ahead_since

    def _path_blocked(self, pose: Pose2D, hits: np.ndarray) -> bool:
        assert self.follower is not None
        path = self.follower.path
        along, _gap = path.project(pose.x, pose.y)
        ahead = path.sample(along + 0.3, along + self.settings.look_ahead, 0.1)
        if len(ahead) == 0 or len(hits) == 0:
            return False
        return bool(any_within(hits, ahead, self.planner.footprint.inscribed_radius + 0.05))

    def _replan(self, now: float, pose: Pose2D, hits: np.ndarray, discs: np.ndarray) -> None:
        """Plan past what the laser sees and the discs; wait if only the discs are in the way."""
        self._replanned_at, self._ahead_since = now, None
        result = self._plan_around(pose, hits, discs)
        if result.path is not None:  # a detour may be longer: progress counts from here on,
            self.replans += 1           # but the stall clock keeps running
            self.follower = PathFollower(result.path, self.use_heading, self.settings.follower)
            self._best = result.length
        elif len(discs):
            self._start_waiting(now, len(discs), self.follower.path if self.follower else None)
