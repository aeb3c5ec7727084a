"""Goal queries that write the blackboard: ``ClosestGoal`` and ``DistanceToGoal``.

Both ask the robot's navigation services in the background (the tick never waits for the
planner); they are RUNNING until the answer comes, normally the next tick.

* ``ClosestGoal{key}`` writes the name of the goal with the shortest *planned path* to ``key``
  (default ``closest_goal``) and its length to ``<key>_distance``; FAILURE when no goal can be
  reached.
* ``DistanceToGoal{location, key, below}`` writes the planned path length to ``location`` into
  ``key`` (default ``distance_to_<location>``): SUCCESS when a path exists and is shorter than
  ``below`` metres (no limit by default), FAILURE otherwise — so it also works as a condition
  ("is the kitchen within 20 m?").
"""

from __future__ import annotations

import math
from concurrent.futures import Future
from typing import Any

from typing_extensions import override

from cyborg.bt import FAILURE, RUNNING, SUCCESS, Action, Condition, Status, register
from cyborg.robot.protocol import ROBOT, robot_of


class _Query:
    """A question to the robot, asked at the start of an activation and polled in ticks."""

    future: Future[Any] | None = None

    def result(self) -> Any:
        """The answer; None while it is not there. Raises what the question raised."""
        future = self.future
        if future is None or not future.done():
            return None
        return future.result()


@register
class ClosestGoal(Action, _Query):
    """Write the closest reachable goal (by path length) to the blackboard."""

    requires = (ROBOT,)

    def __init__(self, key: str = "closest_goal") -> None:
        if not key:
            raise ValueError("key is empty: name the blackboard entry to write")
        self.key = key

    @override
    def on_start(self) -> None:
        self.future = robot_of(self).closest_goal()

    @override
    def tick(self) -> Status:
        answer = self.result()
        if answer is None:
            return RUNNING
        name, distance = answer
        self.blackboard[self.key] = name if math.isfinite(distance) else None
        self.blackboard[f"{self.key}_distance"] = distance
        return SUCCESS if name and math.isfinite(distance) else FAILURE


@register
class DistanceToGoal(Condition, _Query):
    """Write the path length to ``location``; succeed when it is below ``below`` metres."""

    requires = (ROBOT,)

    def __init__(self, location: str, key: str = "", below: float = math.inf) -> None:
        if not location:
            raise ValueError("location is empty: give the name of a goal on the map")
        self.location = location
        self.key = key or f"distance_to_{location}"
        self.below = below

    def on_start(self) -> None:
        """Asks for the path to ``location``; raises KeyError when the map has no such goal."""
        robot = robot_of(self)
        goal = robot.goals().get(self.location) or robot.goals(refresh=True).get(self.location)
        if goal is None:
            raise KeyError(f"no goal named {self.location!r} on the map")
        self.future = robot.distance_to(goal.pose)

    @override
    def tick(self) -> Status:
        distance = self.result()
        if distance is None:
            return RUNNING
        self.blackboard[self.key] = distance
        return SUCCESS if math.isfinite(distance) and distance < self.below else FAILURE
