"""What the robot sees and says, as behaviour nodes ask it: tracked objects, speech, turning.

The perception nodes (``ObjectDetected``, ``ClosestObject``, ``FaceObject``,
``ApproachObject``, ``Say``) need more of the robot than driving to goals: the objects its
tracker follows on the map (:class:`SeenObject`, from the ``objects`` topic of
:mod:`cyborg.interfaces.perception`), a voice (the ``say`` topic) and direct speed commands
(``cmd_vel``) to turn toward someone. :class:`PerceivingRobot` is that part of the robot;
:class:`~cyborg.robot.bus_robot.BusRobot` offers it, and :func:`perceiving_robot_of` fetches it
for a node with a clear error when the tree's robot lacks it.

**Ages without a shared clock.** An object's age is the time between its last sighting and the
stamp of the list it came in (the tracker's time when it published, at least once a second), so
neither the tree nor the robot client need run on the detector's clock. A list that stops
coming (the tracker is gone) counts as empty after
:data:`~cyborg.robot.bus_perception.STALE_AFTER` wall-clock seconds.

:func:`choose` picks the object a node acts on: of a label, fresh and confident enough, the
nearest to the robot now (by its current pose and the object's map position).
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any, Protocol

from cyborg.bt import Node
from cyborg.nav.geometry import Pose2D
from cyborg.robot.protocol import RobotError, robot_of


@dataclass(frozen=True)
class SeenObject:
    """One tracked object as of the list it came in (metres, radians, seconds, map frame)."""

    id: int
    label: str
    confidence: float
    """0..1, decayed to the list's stamp."""
    x: float
    y: float
    vx: float
    vy: float
    age: float
    """Seconds since it was last seen, as of the list's stamp."""
    times_seen: int
    distance: float
    """From the robot's centre, at last sight."""
    bearing: float
    """From the robot's heading at last sight, positive left."""

    def seen_from(self, pose: Pose2D | None) -> tuple[float, float]:
        """``(distance, bearing)`` from a robot at ``pose`` now; at last sight without one."""
        if pose is None:
            return self.distance, self.bearing
        dx, dy = self.x - pose.x, self.y - pose.y
        bearing = math.remainder(math.atan2(dy, dx) - pose.theta, 2 * math.pi)
        return math.hypot(dx, dy), bearing

    def as_entry(self, pose: Pose2D | None) -> dict[str, Any]:
        """What ``ClosestObject`` writes to the blackboard: plain values a template can use."""
        distance, bearing = self.seen_from(pose)
        return {"id": self.id, "label": self.label, "confidence": self.confidence,
                "distance": distance, "bearing": bearing, "x": self.x, "y": self.y,
                "age": self.age}


class PerceivingRobot(Protocol):
    """The robot as the perception nodes need it."""

    @property
    def pose(self) -> Pose2D | None:
        """The robot's last known pose; None before the first."""
        ...
    def objects(self) -> list[SeenObject]:
        """The objects its tracker follows now (empty before the first list, or when stale)."""
        ...
    def say(self, text: str) -> None:
        """Have the robot speak ``text`` (published for a speech node; never waits)."""
        ...
    def drive(self, linear: float, angular: float) -> None:
        """Drive at ``linear`` m/s, turning at ``angular`` rad/s (left positive), for now.

        A command holds until the next one and cancels a goal; ``drive(0, 0)`` stops.
        """
        ...


def perceiving_robot_of(node: Node) -> PerceivingRobot:
    """The tree's robot, if it sees and speaks; a RobotError naming the node when it does not."""
    robot = robot_of(node)
    missing = [name for name in ("objects", "say", "drive") if not hasattr(robot, name)]
    if missing:
        raise RobotError(f"{node.name} needs a robot that sees and speaks; this tree's robot "
                         f"({type(robot).__name__}) has no {', '.join(missing)}")
    return robot  # type: ignore[return-value]


def choose(objects: Iterable[SeenObject], label: str, pose: Pose2D | None, *,
           min_confidence: float = 0.0, max_age: float = math.inf,
           max_distance: float = math.inf, object_id: int | None = None) -> SeenObject | None:
    """The nearest object of ``label`` (any label when empty) that passes every limit.

    With ``object_id`` only that object qualifies (a node following one object keeps it).
    """
    best: SeenObject | None = None
    best_distance = math.inf
    for item in objects:
        if (label and item.label != label) or (object_id is not None
                                                and item.id != object_id):
            continue
        if item.confidence < min_confidence or item.age > max_age:
            continue
        distance = item.seen_from(pose)[0]
        if distance <= max_distance and distance < best_distance:
            best, best_distance = item, distance
    return best


def check_limits(**limits: float) -> None:
    """Refuses a negative or NaN limit (``maxDistance``, ``minConfidence`` ...) by its name."""
    for name, value in limits.items():
        if math.isnan(value) or value < 0:
            raise ValueError(f"{name} must be a number >= 0, not {value}")
