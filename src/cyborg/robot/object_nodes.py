"""Conditions and queries on what the robot sees: ``ObjectDetected`` and ``ClosestObject``.

Both read the objects the robot's tracker follows on the map (:mod:`cyborg.robot.perceiving`),
so they work the same on the simulator's camera and on the real detector.

* ``ObjectDetected{label, maxDistance, minConfidence, maxAge}`` (condition) — SUCCESS while an
  object of ``label`` (any label when empty) is within ``maxDistance`` metres of the robot
  (no limit by default), at least ``minConfidence`` sure (0..1, default 0.5: an object seen once
  by a confident detector is not yet enough) and seen at most ``maxAge`` seconds ago (default
  1); FAILURE otherwise. It never waits.
* ``ClosestObject{label, key}`` (action) — writes the nearest such object (``minConfidence``
  and ``maxAge`` as above) to the blackboard entry ``key`` (default ``closest``) as a mapping:
  ``label``, ``id``, ``distance`` (m, from the robot's centre now), ``bearing`` (rad from the
  robot's heading, positive left), ``x`` and ``y`` (m on the map), ``confidence`` and ``age``
  (s); ``Say{text=Hello {closest.label}!}`` reads it. SUCCESS when there is one; FAILURE, with
  the entry set to None, when there is none.
"""

from __future__ import annotations

import math

from typing_extensions import override

from cyborg.bt import FAILURE, SUCCESS, Action, Condition, Status, register
from cyborg.robot.perceiving import check_limits, choose, perceiving_robot_of
from cyborg.robot.protocol import ROBOT

MIN_CONFIDENCE = 0.5
"""An object's tracked confidence the nodes ask for unless told otherwise."""
MAX_AGE = 1.0
"""Seconds since an object was last seen that the nodes accept unless told otherwise."""


@register
class ObjectDetected(Condition):
    """Succeed while an object of ``label`` is near, sure and fresh enough; see the module."""

    requires = (ROBOT,)

    def __init__(self, label: str = "", max_distance: float = math.inf,
                 min_confidence: float = MIN_CONFIDENCE, max_age: float = MAX_AGE) -> None:
        check_limits(maxDistance=max_distance, minConfidence=min_confidence, maxAge=max_age)
        self.object_label, self.max_distance = label, max_distance
        self.min_confidence, self.max_age = min_confidence, max_age

    @override
    def tick(self) -> Status:
        robot = perceiving_robot_of(self)
        found = choose(robot.objects(), self.object_label, robot.pose,
                       min_confidence=self.min_confidence, max_age=self.max_age,
                       max_distance=self.max_distance)
        return SUCCESS if found is not None else FAILURE


@register
class ClosestObject(Action):
    """Write the nearest object of ``label`` to the blackboard entry ``key``; see the module."""

    requires = (ROBOT,)

    def __init__(self, label: str = "", key: str = "closest",
                 min_confidence: float = MIN_CONFIDENCE, max_age: float = MAX_AGE) -> None:
        if not key:
            raise ValueError("key is empty: name the blackboard entry to write")
        check_limits(minConfidence=min_confidence, maxAge=max_age)
        self.object_label, self.key = label, key
        self.min_confidence, self.max_age = min_confidence, max_age

    @override
    def tick(self) -> Status:
        robot = perceiving_robot_of(self)
        pose = robot.pose
        found = choose(robot.objects(), self.object_label, pose, min_confidence=self.min_confidence,
                       max_age=self.max_age)
        self.blackboard[self.key] = None if found is None else found.as_entry(pose)
        return SUCCESS if found is not None else FAILURE
