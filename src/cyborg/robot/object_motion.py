"""Moving with respect to what the robot sees: ``FaceObject`` and ``ApproachObject``.

Both pick the nearest object of ``label`` (any label when empty) that the tracker follows
(:mod:`cyborg.robot.perceiving`; at least ``minConfidence`` sure, default 0.3, seen at most
``maxAge`` seconds ago, default 2), keep to that one object (its id) for the whole activation,
and steer by speed commands (``cmd_vel``, sent every tick: the robot stops by itself half a
second after the last one), with the bearing and distance from the robot's pose now to the
object's position on the map:

* ``FaceObject{label, tolerance}`` turns on the spot toward it, at a rate proportional to the
  bearing (:data:`TURN_GAIN` per second, at least :data:`MIN_TURN_RATE` and at most the robot's
  :data:`~cyborg.interfaces.robot.TELEOP_MAX_TURN_RATE`): RUNNING while turning, SUCCESS once
  the bearing is within ``tolerance`` radians (default 0.15, about 9°), FAILURE when there is
  no such object or it is lost (forgotten, or unseen for longer than ``maxAge``).
* ``ApproachObject{label, stopDistance}`` drives toward it — turning first while it is more
  than 45° off, then ahead at a speed that falls with the distance left (never below
  :data:`MIN_SPEED`) — and succeeds once within ``stopDistance`` metres of the robot's centre
  (default 1.0); FAILURE when it is lost. It drives
  straight at the object without a path (the robot still stops before what its laser sees):
  for the last metres, after ``MoveTo`` has brought it near.

Halting either (a higher branch took over, the tree was disabled) stops the robot if the node
was moving it; a node that never moved it sends nothing, so it never cancels someone else's
goal. A speed command cancels the robot's current goal, as driving by hand does.
"""

from __future__ import annotations

import math

from typing_extensions import override

from cyborg.bt import FAILURE, RUNNING, SUCCESS, Action, Status, register
from cyborg.interfaces.robot import TELEOP_MAX_SPEED, TELEOP_MAX_TURN_RATE
from cyborg.robot.perceiving import (
    PerceivingRobot,
    SeenObject,
    check_limits,
    choose,
    perceiving_robot_of,
)
from cyborg.robot.protocol import ROBOT

MIN_CONFIDENCE = 0.3
"""The confidence a moving node asks for unless told otherwise (it follows a known object)."""
MAX_AGE = 2.0
"""Seconds unseen after which a moving node gives its object up, unless told otherwise."""
TURN_GAIN = 1.5
"""Turn rate per radian of bearing, 1/s."""
MIN_TURN_RATE = 0.15
"""The slowest turn, rad/s, so that a small bearing is still closed."""
SPEED_GAIN = 0.5
"""Forward speed per metre beyond the stop distance, 1/s."""
MIN_SPEED = 0.05
"""The slowest approach, m/s, so that the last centimetres are closed too."""
TURN_FIRST = math.pi / 4
"""Bearing beyond which ``ApproachObject`` turns on the spot before driving."""


def turn_rate(bearing: float) -> float:
    """The turn toward ``bearing`` (rad, left positive): proportional, bounded both ways."""
    rate = min(TELEOP_MAX_TURN_RATE, max(MIN_TURN_RATE, TURN_GAIN * abs(bearing)))
    return math.copysign(rate, bearing)


class _Follow(Action):
    """Picks an object at the start and keeps to it; stops the robot when halted."""

    requires = (ROBOT,)

    def __init__(self, label: str, min_confidence: float, max_age: float) -> None:
        check_limits(minConfidence=min_confidence, maxAge=max_age)
        self.object_label, self.min_confidence, self.max_age = label, min_confidence, max_age
        self.target: int | None = None
        self.moving = False
        self.reason = ""

    @override
    def on_start(self) -> None:
        self.target, self.moving, self.reason = None, False, ""

    def _object(self, robot: PerceivingRobot) -> SeenObject | None:
        found = choose(robot.objects(), self.object_label, robot.pose,
                       min_confidence=self.min_confidence, max_age=self.max_age,
                       object_id=self.target)
        if found is None:
            what = f"{self.object_label or 'object'}" + (f" {self.target}" if self.target else "")
            self.reason = (f"lost the {what}" if self.target is not None
                           else f"no {what} in sight")
        else:
            self.target = found.id
        return found

    def _drive(self, robot: PerceivingRobot, linear: float, angular: float) -> None:
        robot.drive(linear, angular)
        self.moving = bool(linear or angular)

    def _stop(self, robot: PerceivingRobot) -> None:
        if self.moving:
            self._drive(robot, 0.0, 0.0)

    @override
    def on_halt(self) -> None:
        if self.moving:
            self._stop(perceiving_robot_of(self))


@register
class FaceObject(_Follow):
    """Turn the robot toward the nearest object of ``label``; see the module docstring."""

    def __init__(self, label: str = "", tolerance: float = 0.15,
                 min_confidence: float = MIN_CONFIDENCE, max_age: float = MAX_AGE) -> None:
        if not (math.isfinite(tolerance) and tolerance > 0):
            raise ValueError(f"tolerance must be a positive number of radians, not {tolerance}")
        super().__init__(label, min_confidence, max_age)
        self.tolerance = tolerance

    @override
    def tick(self) -> Status:
        robot = perceiving_robot_of(self)
        found = self._object(robot)
        if found is None:
            self._stop(robot)
            return FAILURE
        _distance, bearing = found.seen_from(robot.pose)
        if abs(bearing) <= self.tolerance:
            self._stop(robot)
            return SUCCESS
        self._drive(robot, 0.0, turn_rate(bearing))
        return RUNNING


@register
class ApproachObject(_Follow):
    """Drive up to the nearest object of ``label``; see the module docstring."""

    def __init__(self, label: str = "", stop_distance: float = 1.0,
                 min_confidence: float = MIN_CONFIDENCE, max_age: float = MAX_AGE) -> None:
        if not (math.isfinite(stop_distance) and stop_distance >= 0):
            raise ValueError(f"stopDistance must be a number of metres >= 0, not "
                             f"{stop_distance}")
        super().__init__(label, min_confidence, max_age)
        self.stop_distance = stop_distance

    @override
    def tick(self) -> Status:
        robot = perceiving_robot_of(self)
        found = self._object(robot)
        if found is None:
            self._stop(robot)
            return FAILURE
        distance, bearing = found.seen_from(robot.pose)
        if distance <= self.stop_distance:
            self._stop(robot)
            return SUCCESS
        speed = 0.0 if abs(bearing) > TURN_FIRST else \
            max(MIN_SPEED, min(TELEOP_MAX_SPEED, SPEED_GAIN * (distance - self.stop_distance))
                ) * math.cos(bearing)
        angular = turn_rate(bearing) if abs(bearing) > 0.02 else 0.0
        self._drive(robot, speed, angular)
        return RUNNING
