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
  at most ``retries`` times, and then the node fails. While the robot is docking or undocking
  the timer waits;
* fails at once when the goal does not exist or cannot be reached (no path);
* cancels its goal when it is halted (a higher-priority branch took over, the tree was
  disabled), so an abandoned MoveTo never leaves the robot driving.

All times are in the tree's clock: simulated seconds when the tree runs on ``/clock``.
Unlike the 2018 node, the result is reset on every activation, timers are one-shot deadlines
checked in the tick, the heading comes from the map, and the progress check never blocks.
"""

from __future__ import annotations

import logging

from cyborg.bt import FAILURE, RUNNING, SUCCESS, Action, Status, register
from cyborg.nodes.robot import (
    ROBOT,
    DockState,
    Goal,
    Move,
    MoveOutcome,
    RobotError,
    heading_error,
    robot_of,
)

log = logging.getLogger("cyborg.nodes")

PROGRESS_EPSILON = 0.01
"""Metres the remaining path must shrink by to count as progress (feedback noise)."""


@register
class MoveTo(Action):
    """Drive to the map goal ``location``; see the module docstring."""

    requires = (ROBOT,)

    def __init__(self, location: str, radius: float = 0.5, start_timeout: float = 10.0,
                 progress_timeout: float = 15.0, retries: int = 2,
                 heading_tolerance: float = 0.35) -> None:
        if not location:
            raise ValueError("location is empty: give the name of a goal on the map")
        if radius < 0 or start_timeout <= 0 or progress_timeout <= 0 or retries < 0:
            raise ValueError("radius and retries must be >= 0, the timeouts > 0")
        self.location = location
        self.radius = radius
        self.start_timeout = start_timeout
        self.progress_timeout = progress_timeout
        self.retries = retries
        self.heading_tolerance = heading_tolerance
        self.move: Move | None = None
        self.goal: Goal | None = None
        self.attempt = 0
        self.reason = ""
        self._best = float("inf")
        self._deadline = 0.0

    # ------------------------------------------------------------------ lifecycle
    def on_start(self) -> None:
        self.move, self.goal, self.attempt, self.reason = None, None, 0, ""
        robot = robot_of(self)
        goals = robot.goals()
        if self.location not in goals:
            goals = robot.goals(refresh=True)  # the map may have changed
        self.goal = goals.get(self.location)
        if self.goal is None:
            self.reason = (f"no goal named {self.location!r} on the map; goals: "
                           f"{', '.join(sorted(goals)) or 'none'}")
            log.warning("MoveTo %s: %s", self.uid, self.reason)
            return
        self._send()

    def tick(self) -> Status:
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
        if self.now > self._deadline:
            waited = self.progress_timeout if self._best < float("inf") else self.start_timeout
            return self._retry(f"no progress along the path for {waited:g} s")
        return RUNNING

    def on_end(self, status: Status) -> None:
        if self.move is not None:
            self.move.cancel()  # harmless when the move is over; stops the robot otherwise
        if status is FAILURE and self.reason:
            log.warning("MoveTo %s (%s) failed: %s", self.location, self.uid, self.reason)

    def on_halt(self) -> None:
        if self.move is not None:
            self.move.cancel()

    # ------------------------------------------------------------------ steps
    def _send(self) -> None:
        self.attempt += 1
        self._best = float("inf")
        self._deadline = self.now + self.start_timeout
        try:
            self.move = robot_of(self).move_to(self.location)
        except RobotError as exc:
            self.move, self.reason = None, str(exc)

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
        log.info("MoveTo %s: %s; trying again (%d of %d)", self.location, why,
                 self.attempt, self.retries)
        self._send()
        return RUNNING if self.move is not None else FAILURE
