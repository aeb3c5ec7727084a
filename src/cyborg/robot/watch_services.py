"""Services that keep the robot's state in the blackboard: ``BatteryWatch`` and ``ClosestGoal``.

Attach them to a composite in behavior3editor (its ``services`` property, see
docs/services.md) and the conditions below it read plain blackboard keys instead of asking the
robot::

    services = "BatteryWatch(interval=1); ClosestGoal(key=closest, interval=5)"

* ``BatteryWatch{key, low}`` writes the last battery reading, each run: ``<key>`` (default
  ``battery``) as a dict ``{"percent", "charging", "docked", "dock_state", "low", "time"}``
  (``battery.percent < 20`` in a mode's condition or a behavior3 1.x ``Check``), and the flat
  keys ``<key>_percent`` and ``<key>_low`` (percent below ``low``, default 25) for nodes that
  compare one key (``BlackboardCompare{key: battery_low, value: true}``). Before the robot's
  first reading it writes nothing.
* ``ClosestGoal{key}`` writes the name of the goal with the shortest planned path to ``<key>``
  (default ``closest_goal``; ``None`` when no goal can be reached) and its length in metres to
  ``<key>_distance``, as the action node of the same name does. The question goes to the
  robot's navigation services in the background: each run writes the answer to the last
  question (at once when it is there already) and asks again, so no run waits for the planner.
  A question the robot could not take is logged (once per 10 s) and asked again next run.

Both need the robot in the blackboard's resources (``"robot"``), as the robot's nodes do.
"""

from __future__ import annotations

import logging
import math
from concurrent.futures import Future
from typing import Any

from cyborg.bt import Service, ServiceBoard, register_service
from cyborg.robot.protocol import ROBOT, DockState, Robot, RobotError
from cyborg.robot.rate_limited_log import RateLimitedLog

log = logging.getLogger("cyborg.robot")
limited = RateLimitedLog(log)


def robot_in(blackboard: ServiceBoard, service: Service) -> Robot:
    """The robot a service's tree acts on; a clear error when the tree has none."""
    robot: Robot | None = blackboard.resources.get(ROBOT)
    if robot is None:
        raise RobotError(f"{service.name} needs a robot to watch, and this tree has none: run it "
                         "with `cyborg bt serve` or `cyborg up`, or give the tree "
                         "Blackboard(resources={'robot': ...})")
    return robot


@register_service
class BatteryWatch(Service):
    """Writes the robot's battery state to the blackboard at each run."""

    interval = 1.0
    requires = (ROBOT,)

    def __init__(self, key: str = "battery", low: float = 25.0) -> None:
        if not key:
            raise ValueError("key is empty: name the blackboard entry to write")
        if not 0 <= low <= 100:
            raise ValueError(f"low is a percentage (0 to 100), not {low}")
        self.key = key
        self.low = low

    def run(self, blackboard: ServiceBoard) -> None:
        """Writes ``<key>``, ``<key>_percent`` and ``<key>_low`` from the last reading."""
        reading = robot_in(blackboard, self).battery
        if reading is None:
            return
        low = reading.charge_percent < self.low
        blackboard[self.key] = {
            "percent": reading.charge_percent, "charging": reading.charging,
            "docked": reading.dock_state is DockState.DOCKED,
            "dock_state": reading.dock_state.name.lower(), "low": low, "time": reading.time}
        blackboard[f"{self.key}_percent"] = reading.charge_percent
        blackboard[f"{self.key}_low"] = low


@register_service("ClosestGoal")
class ClosestGoalWatch(Service):
    """Writes the closest reachable goal (by path length) and its distance at each run."""

    interval = 2.0
    requires = (ROBOT,)

    def __init__(self, key: str = "closest_goal") -> None:
        if not key:
            raise ValueError("key is empty: name the blackboard entry to write")
        self.key = key
        self._asked: Future[tuple[str, float]] | None = None

    def on_activate(self, blackboard: ServiceBoard) -> None:
        """Forgets a question left from an earlier activation."""
        self._asked = None

    def run(self, blackboard: ServiceBoard) -> None:
        """Writes the answer to the last question if it came, then asks again."""
        if self._asked is not None and self._asked.done():
            self._write(blackboard, self._asked)
        if self._asked is None:
            try:
                self._asked = robot_in(blackboard, self).closest_goal()
            except RobotError as exc:
                limited.warning(("ClosestGoal", self.composite_uid), "ClosestGoal on %s: %s",
                                self.composite_uid, exc)
                return
            if self._asked.done():
                self._write(blackboard, self._asked)

    def on_deactivate(self, blackboard: ServiceBoard) -> None:
        """Drops the question in flight: its answer would come after the branch ended."""
        self._asked = None

    def _write(self, blackboard: ServiceBoard, answer: Future[Any]) -> None:
        self._asked = None
        try:
            name, distance = answer.result()
        except RobotError as exc:
            limited.warning(("ClosestGoal", self.composite_uid), "ClosestGoal on %s: %s",
                            self.composite_uid, exc)
            return
        reachable = bool(name) and math.isfinite(distance)
        blackboard[self.key] = name if reachable else None
        blackboard[f"{self.key}_distance"] = distance
