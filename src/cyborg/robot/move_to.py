"""``MoveTo{location, radius}``: drive to a named goal of the map.

The node looks the goal up among the map's goals (AvailableGoals), sends the robot there with
the move_to_goal action (the robot turns to the goal's heading when the map gives one), and

* succeeds when the action succeeds, or as soon as the robot is within ``radius`` metres of
  the goal (and, for a goal with a heading, faces it within ``heading_tolerance`` radians) —
  the move is then cancelled so the robot stops there;
* watches progress along the planned path: the remaining path length (from the action's
  feedback) must get shorter. A detour around an obstacle therefore still counts as
  progress. Without progress for ``start_timeout`` seconds after a start, or
  ``progress_timeout`` seconds after the last progress, the move is cancelled and sent again,
  at most ``retries`` times, and then the node fails. While the robot is docking or undocking,
  or waits for people or objects to make way (path state ``WAITING_FOR_PATH``: the robot's
  navigator gives up on its own after its wait limit), the timer waits;
* fails at once when the goal does not exist or cannot be reached (no path);
* **backs off when the robot is not reachable** — the move_to_goal action server or the map's
  goal service is not there (the simulator was killed, the robot's computer restarts): it stays
  RUNNING and tries again after ``retry_delay`` seconds (editor: ``retryDelay``, 2), doubling
  the wait after each unreachable try up to ``retry_delay_max`` (``retryDelayMax``, 30). Each
  try counts against ``retries``; when they are used up the node fails, and the back-off
  carries over to its next activation: a Repeater that starts it again at once finds it
  RUNNING, waiting out the rest of the delay before it asks the robot again. So a patrol whose
  robot is gone asks it about once per ``retry_delay_max`` and logs a few lines a minute
  instead of failing (and warning) ten times a second; when the robot is back, the patrol goes
  on at the next try. The first move that gets through resets the back-off;
* cancels its goal when it is halted (a higher-priority branch took over, the tree was
  disabled), so an abandoned MoveTo never leaves the robot driving.

Failures and retries are logged rate-limited (:class:`~cyborg.robot.rate_limited_log.
RateLimitedLog`): one line per kind per 10 s of wall time, with the count of those left out.
A blocked goal is reported once: when the node fails again for the same reason, with no success
between (a patrol that comes back to a goal whose way stays blocked), it only counts, and
says once how often and for how long (tree clock) when that ends — the goal reached, another
failure, or the node halted.

All times are in the tree's clock: simulated seconds when the tree runs on ``/clock``; the
node never sleeps, it compares deadlines in its ticks. Unlike the 2018 node, the result is reset
on every activation, timers are one-shot deadlines checked in the tick, the heading comes from
the map, and the progress check never blocks.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Hashable

from typing_extensions import override

from cyborg.bt import FAILURE, RUNNING, SUCCESS, Action, Status, register
from cyborg.robot.protocol import (
    ROBOT,
    DockState,
    Goal,
    Move,
    MoveOutcome,
    RobotError,
    heading_error,
    robot_of,
)
from cyborg.robot.rate_limited_log import RateLimitedLog

log = logging.getLogger("cyborg.robot")
limited = RateLimitedLog(log)

UNREACHABLE = "MoveTo: robot not reachable"
"""The log kind of "robot not reachable", with the robot's id: one fact about the robot, one
line for all MoveTo nodes."""

PROGRESS_EPSILON = 0.01
"""Metres the remaining path must shrink by to count as progress (feedback noise)."""


@register
class MoveTo(Action):
    """Drive to the map goal ``location``; see the module docstring."""

    requires = (ROBOT,)

    def __init__(self, location: str, radius: float = 0.5, start_timeout: float = 10.0,
                 progress_timeout: float = 15.0, retries: int = 2,
                 heading_tolerance: float = 0.35, retry_delay: float = 2.0,
                 retry_delay_max: float = 30.0) -> None:
        if not location:
            raise ValueError("location is empty: give the name of a goal on the map")
        if radius < 0 or start_timeout <= 0 or progress_timeout <= 0 or retries < 0:
            raise ValueError("radius and retries must be >= 0, the timeouts > 0")
        if not (math.isfinite(retry_delay) and retry_delay > 0):
            raise ValueError(f"retryDelay must be a positive number of seconds, not "
                             f"{retry_delay}")
        if not (math.isfinite(retry_delay_max) and retry_delay_max >= retry_delay):
            raise ValueError(f"retryDelayMax ({retry_delay_max}) must be a number of seconds "
                             f"no less than retryDelay ({retry_delay})")
        self.location = location
        self.radius = radius
        self.start_timeout = start_timeout
        self.progress_timeout = progress_timeout
        self.retries = retries
        self.heading_tolerance = heading_tolerance
        self.retry_delay, self.retry_delay_max = retry_delay, retry_delay_max
        self.move: Move | None = None
        self.goal: Goal | None = None
        self.attempt = 0
        self.reason = ""
        self._best = float("inf")
        self._deadline = 0.0
        self._retry_at: float | None = None  # waiting to try the unreachable robot again
        self._failure: Hashable = ()  # the log kind of the failure in ``reason``
        # the back-off outlives an activation: the robot is as unreachable as a tick ago
        self._delay = 0.0
        self._next_try = -math.inf
        self._repeated: tuple[str, int, float] | None = None  # reason, repeats, first at

    # ------------------------------------------------------------------ lifecycle
    @override
    def on_start(self) -> None:
        self.move, self.goal, self.attempt, self.reason = None, None, 0, ""
        self._retry_at, self._failure = None, ("MoveTo failed", self.uid)
        if self.now < self._next_try:  # the robot was not reachable a moment ago
            self._retry_at = self._next_try
            self.reason = (f"waiting {self._next_try - self.now:.3g} s before asking the robot "
                           "again: it was not reachable")
            return
        self._start()

    @override
    def tick(self) -> Status:
        self._after_clock_went_back()
        if self.move is None and self._retry_at is not None:
            if self.now < self._retry_at:
                return RUNNING  # backing off
            self._retry_at = None
            self._start()
            if self.move is None:
                return RUNNING if self._retry_at is not None else FAILURE
        move, goal = self.move, self.goal
        if move is None or goal is None:
            return FAILURE
        robot = robot_of(self)
        if self._arrived(goal):
            return SUCCESS
        if move.done:
            return self._finished(move)
        if move.remaining < self._best - PROGRESS_EPSILON:
            self._best = move.remaining
            self._deadline = self.now + self.progress_timeout
        battery = robot.battery
        if battery is not None and battery.dock_state not in (DockState.UNDOCKED,
                                                              DockState.UNKNOWN):
            self._deadline = max(self._deadline, self.now + self.start_timeout)
        if move.waiting:  # for someone to make way: the robot's own wait limit applies
            self._deadline = max(self._deadline, self.now + self.progress_timeout)
        if self.now > self._deadline:
            waited = self.progress_timeout if self._best < float("inf") else self.start_timeout
            return self._retry(f"no progress along the path for {waited:g} s")
        return RUNNING

    @override
    def on_end(self, status: Status) -> None:
        if self.move is not None:
            self.move.cancel()  # harmless when the move is over; stops the robot otherwise
        if status is FAILURE and self.reason:
            if self._repeated is not None and self._repeated[0] == self.reason:
                reason, repeats, since = self._repeated
                self._repeated = (reason, repeats + 1, since)
                log.debug("MoveTo %s (%s) failed again: %s", self.location, self.uid, reason)
                return
            self._summarise("failed otherwise")
            self._repeated = (self.reason, 0, self.now)
            limited.warning(self._failure, "MoveTo %s (%s) failed: %s", self.location, self.uid,
                            self.reason)
        elif status is SUCCESS:
            self._summarise("reached the goal")

    @override
    def on_halt(self) -> None:
        if self.move is not None:
            self.move.cancel()
        self._summarise("was halted")

    def _summarise(self, ending: str) -> None:
        """Say how often the failure reported once came again, now that it ended so."""
        if self._repeated is None:
            return
        reason, repeats, since = self._repeated
        self._repeated = None
        if repeats:
            log.info("MoveTo %s (%s) failed %d more times in %.0f s alike, then %s: %s",
                     self.location, self.uid, repeats, self.now - since, ending, reason)

    def _after_clock_went_back(self) -> None:
        """Counts again from now if the clock went back (a restarted simulation, a /clock jump).

        A deadline further away than it can be set means the clock went back: count again from
        now, as ROS 2 resets its timers, instead of waiting for time to pass the old start again.
        """
        now = self.now
        if self._deadline - now > max(self.progress_timeout, self.start_timeout):
            self._deadline = now + self.start_timeout
        if self._retry_at is not None and self._retry_at - now > self._delay:
            self._retry_at = now + self._delay
        if self._next_try - now > self._delay:
            self._next_try = now + self._delay

    # ------------------------------------------------------------------ steps
    def _start(self) -> None:
        """Look the goal up (once per activation) and send the robot there."""
        if self.goal is None:
            robot = robot_of(self)
            try:
                goals = robot.goals()
                if self.location not in goals:
                    goals = robot.goals(refresh=True)  # the map may have changed
            except RobotError as exc:
                self.attempt += 1
                self._unreachable(str(exc))
                return
            self.goal = goals.get(self.location)
            if self.goal is None:
                self.reason = (f"no goal named {self.location!r} on the map; goals: "
                               f"{', '.join(sorted(goals)) or 'none'}")
                return
        self._send()

    def _send(self) -> None:
        robot = robot_of(self)
        self.attempt += 1
        self._best = float("inf")
        self._deadline = self.now + self.start_timeout
        try:
            self.move = robot.move_to(self.location)
        except RobotError as exc:
            self.move = None
            self._unreachable(str(exc))
            return
        self._delay, self._next_try = 0.0, -math.inf  # reachable: no back-off next time
        self._failure = ("MoveTo failed", self.uid)

    def _unreachable(self, why: str) -> None:
        """The robot did not take the request: wait before the next try, longer each time."""
        self._delay = min(self._delay * 2, self.retry_delay_max) if self._delay \
            else self.retry_delay
        self._next_try = self.now + self._delay
        self._failure = (UNREACHABLE, "failed", id(robot_of(self)))
        if self.attempt > self.retries:
            self._retry_at = None
            self.reason = f"{why}; tried {self.attempt} times"
            return
        self._retry_at = self._next_try
        self.reason = (f"{why}; trying again in {self._delay:g} s (retry {self.attempt} of "
                       f"{self.retries})")
        limited.info((UNREACHABLE, "retry", id(robot_of(self))), "MoveTo %s: %s", self.location,
                     self.reason)

    def _arrived(self, goal: Goal) -> bool:
        pose = robot_of(self).pose
        if pose is None or pose.distance_to(goal.pose) > self.radius:
            return False
        return (not goal.has_heading
                or heading_error(pose.theta, goal.pose.theta) <= self.heading_tolerance)

    def _finished(self, move: Move) -> Status:
        outcome = move.outcome
        if outcome is MoveOutcome.SUCCEEDED:
            return SUCCESS
        if outcome is MoveOutcome.NO_PATH:
            self.reason = move.message or "no path to the goal"
            return FAILURE
        return self._retry(f"the robot gave up ({move.message or outcome})")

    def _retry(self, why: str) -> Status:
        if self.move is not None:
            self.move.cancel()
        if self.attempt > self.retries:
            self.reason = f"{why}; tried {self.attempt} times"
            return FAILURE
        limited.info(("MoveTo retry", self.uid), "MoveTo %s: %s; trying again (%d of %d)",
                     self.location, why, self.attempt, self.retries)
        self._send()
        return RUNNING if self.move is not None or self._retry_at is not None else FAILURE
