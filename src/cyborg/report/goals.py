"""The goals a robot drove to in a recording, and how each ended.

What ``cyborg up`` records tells it twice: ``arnl_path_state`` (latched, on change) goes
``PLANNING_PATH`` → ``MOVING_TO_GOAL`` → ``REACHED_GOAL`` or ``FAILED_PLAN`` / ``FAILED_MOVE``
(``ABORTED_PATHPLAN`` when the goal was cancelled), and ``current_goal`` names the goal while the
robot drives to it (an empty name once it is over). The ``move_to_goal`` action's own status and
result travel on hidden topics (``_action/...``), which a recording of all topics leaves out,
as ``ros2 bag record --all`` does; the path state says the same.

:func:`goal_attempts` walks both topics in log-time order: an attempt starts when the path state
leaves a finished state (or a goal is named), ends at the next finished state, and takes its
name from ``current_goal``. Without ``current_goal`` the attempts are still found, unnamed;
without ``arnl_path_state`` each named goal is an attempt whose outcome is unknown.
"""

from __future__ import annotations

import bisect
import math
from dataclasses import dataclass
from enum import StrEnum

from cyborg.interfaces.robot import PathState
from cyborg.report.recording import Stamped

NAME_SLACK_NS = 500_000_000
"""How long after a path state a goal's name may still arrive and belong to it (ns): the two
topics are published one after the other and may be received in either order."""


class Outcome(StrEnum):
    """How a goal attempt ended."""

    REACHED = "reached"
    FAILED = "failed"
    CANCELLED = "cancelled"
    UNFINISHED = "unfinished"
    """Still under way when the recording ended."""
    UNKNOWN = "unknown"
    """Ended, but no path state says how (``arnl_path_state`` was not recorded)."""


PATH_STATES: dict[str, str] = {
    PathState.REACHED_GOAL: "reached: the navigator brought the robot to the goal",
    PathState.FAILED_PLAN: "failed to plan: the map has no way to the goal from where the "
                           "robot was (walls, forbidden areas)",
    PathState.FAILED_MOVE: "failed on the way: the robot made no headway for too long (stuck, "
                           "or people or objects in its way longer than it waits)",
    PathState.ABORTED_PATHPLAN: "cancelled before the navigator finished: in cyborg most often "
                                "a success, as MoveTo stops the robot once it is within its "
                                "radius of the goal (see how far it was left to go); also when "
                                "a higher branch of the tree took over (recharging, a greeting), "
                                "MoveTo sent the goal again after no progress, or STOP",
    PathState.INVALID: "invalid: the navigator could not take the goal",
    PathState.PLANNING_PATH: "still planning when the recording ended",
    PathState.MOVING_TO_GOAL: "still driving when the recording ended",
    PathState.WAITING_FOR_PATH: "waiting for people or objects to make way when the recording "
                                "ended",
}
"""What each path state a goal ends in means, in plain words (the report's legend)."""

_OUTCOMES = {PathState.REACHED_GOAL: Outcome.REACHED, PathState.FAILED_PLAN: Outcome.FAILED,
             PathState.FAILED_MOVE: Outcome.FAILED, PathState.ABORTED_PATHPLAN: Outcome.CANCELLED,
             PathState.INVALID: Outcome.FAILED}


@dataclass
class GoalAttempt:
    """One drive to a goal: when it started and ended (log times, ns), and how."""

    name: str
    start: int
    end: int | None = None
    outcome: Outcome = Outcome.UNFINISHED
    state: str = ""
    """The path state it ended in (``REACHED_GOAL``, ``FAILED_MOVE``, ...)."""
    position: tuple[float, float] | None = None
    """Where the goal is (m, map frame), from ``current_goal``; None when not named there."""
    left: float | None = None
    """Metres from the robot to the goal where it stopped when the attempt ended
    (:func:`measure_left`); None without an end, a goal position or a pose."""


def goal_attempts(path_states: list[Stamped], goals: list[Stamped]) -> list[GoalAttempt]:
    """The attempts in ``arnl_path_state`` and ``current_goal`` messages; see the module."""
    events = sorted([(item.log_time, 0, str(item.message.data), (0.0, 0.0))
                     for item in path_states]
                    + [(item.log_time, 1, str(item.message.name),
                        (float(item.message.position.x), float(item.message.position.y)))
                       for item in goals], key=lambda event: (event[0], event[1]))
    attempts: list[GoalAttempt] = []
    current: GoalAttempt | None = None
    last_state = ""
    for log_time, kind, value, position in events:
        if kind == 1:
            current = _named(attempts, current, log_time, value, bool(path_states))
            named = current if current is not None and current.name == value else None
            if value and named is None and attempts and attempts[-1].name == value:
                named = attempts[-1]
            if named is not None and named.position is None:
                named.position = position
            continue
        state = _state(value)
        if state is None or value == last_state:
            continue
        last_state = value
        if not state.finished:
            if current is None:
                current = GoalAttempt("", log_time)
                attempts.append(current)
            continue
        if state is PathState.NOT_INITIALIZED:
            continue
        if current is None:  # a plan that failed at once: no moving state came before
            current = GoalAttempt("", log_time)
            attempts.append(current)
        current.end, current.outcome, current.state = log_time, _OUTCOMES[state], value
        current = None
    return attempts


def _named(attempts: list[GoalAttempt], current: GoalAttempt | None, log_time: int, name: str,
           states_recorded: bool) -> GoalAttempt | None:
    """Takes one ``current_goal`` message; returns the attempt under way after it."""
    if not name:
        if current is not None and not states_recorded:
            current.end, current.outcome = log_time, Outcome.UNKNOWN
            return None
        return current
    if current is not None and not current.name:
        current.name = name
        return current
    if current is not None and current.name == name:
        return current
    last = attempts[-1] if attempts else None
    if (current is None and last is not None and not last.name and last.end is not None
            and log_time - last.end <= NAME_SLACK_NS):
        last.name = name  # the name came just after a state that ended its attempt
        return None
    if current is not None:  # another goal before this one ended: it was replaced
        current.end = log_time
        current.outcome = Outcome.CANCELLED if states_recorded else Outcome.UNKNOWN
    attempt = GoalAttempt(name, log_time)
    attempts.append(attempt)
    return attempt


def _state(value: str) -> PathState | None:
    try:
        return PathState(value)
    except ValueError:
        return None


def measure_left(attempts: list[GoalAttempt], poses: list[Stamped]) -> None:
    """Sets each ended attempt's :attr:`~GoalAttempt.left` from the robot's pose then.

    The robot stops when an attempt ends (reached, failed or cancelled), so the first pose at
    or after the end is where it stopped (the last before it when none follows): a pose
    published a few times a second under a fast simulator may lie metres behind the robot
    just before. ``poses`` are ``geometry_msgs/Pose2D`` messages in log-time order.
    """
    times = [item.log_time for item in poses]
    for attempt in attempts:
        if attempt.end is None or attempt.position is None or not poses:
            continue
        index = min(bisect.bisect_left(times, attempt.end), len(poses) - 1)
        pose = poses[index].message
        attempt.left = math.dist((float(pose.x), float(pose.y)), attempt.position)


def tally(attempts: list[GoalAttempt]) -> dict[Outcome, int]:
    """How many attempts ended each way (every outcome listed, 0 when none)."""
    counts = dict.fromkeys(Outcome, 0)
    for attempt in attempts:
        counts[attempt.outcome] += 1
    return counts
