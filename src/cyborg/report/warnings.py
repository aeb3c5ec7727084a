"""The warnings of a run: what its log said, and what went wrong that a log would have said.

cyborg's own components log through Python's logging, not onto the bus, so a recording of
``cyborg up`` holds no ``/rosout``. When one is recorded (a ROS 2 node on the same bus, or a
recording of the real robot) its messages of level WARN and above are the log's warnings
(:func:`log_warnings`). For every robot the report adds what the recording itself shows went
wrong (:func:`robot_warnings`): goals that failed, ticks whose root failed (one row per run of
consecutive ticks), nodes that returned error, and bumpers pressed.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from cyborg.report.goals import GoalAttempt, Outcome
from cyborg.report.recording import Stamped
from cyborg.report.tree_stats import TreeHistory

LEVELS = {10: "debug", 20: "info", 30: "warn", 40: "error", 50: "fatal"}
"""``rcl_interfaces/msg/Log`` levels by number."""
WARN = 30
"""The lowest level a report lists."""


@dataclass(frozen=True)
class WarningRow:
    """One row of a warnings table."""

    log_time: int
    level: str
    source: str
    text: str


def log_warnings(messages: list[Stamped]) -> list[WarningRow]:
    """The ``/rosout`` messages of level WARN and above."""
    return [WarningRow(item.log_time, LEVELS.get(int(item.message.level), str(item.message.level)),
                    str(item.message.name), str(item.message.msg))
            for item in messages if int(item.message.level) >= WARN]


def robot_warnings(goals: list[GoalAttempt], tree: TreeHistory,
                   bumpers: list[Stamped]) -> list[WarningRow]:
    """What went wrong for one robot (see the module), in time order."""
    rows = [WarningRow(attempt.end or attempt.start, "warn", "navigation",
                    f"failed to reach {attempt.name or 'a goal'} ({attempt.state})")
            for attempt in goals if attempt.outcome is Outcome.FAILED]
    for run in tree.runs:
        for log_time, first, last in run.failures:
            ticks = f"tick {first}" if first == last else f"ticks {first}-{last}"
            rows.append(WarningRow(log_time, "warn", "tree", f"{run.title}: the root failed in "
                                                          f"{ticks}"))
        rows += [WarningRow(log_time, "error", "tree", f"{label} returned error in tick {tick}")
                 for log_time, tick, label in run.errors]
    rows += _bumper_presses(bumpers)
    return sorted(rows, key=lambda row: row.log_time)


def _bumper_presses(messages: list[Stamped]) -> list[WarningRow]:
    rows, pressed_before = [], False
    for item in messages:
        pressed = _pressed(item.message)
        if pressed and not pressed_before:
            rows.append(WarningRow(item.log_time, "warn", "bumpers", f"{pressed} bumper pressed"))
        pressed_before = bool(pressed)
    return rows


def _pressed(message: Any) -> str:
    front = any(bool(value) for value in message.front_bumpers)
    rear = any(bool(value) for value in message.rear_bumpers)
    return " and ".join(side for side, on in (("front", front), ("rear", rear)) if on)
