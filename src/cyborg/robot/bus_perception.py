"""The robot's eyes, voice and speed commands on the bus, for :class:`~cyborg.robot.BusRobot`.

Under the robot's namespace: ``objects`` (subscribed, the tracker's list:
:mod:`cyborg.interfaces.perception`), ``say`` (published) and ``cmd_vel`` (published:
:data:`cyborg.interfaces.robot.CMD_VEL`). The ``objects`` subscription is made on the first
:meth:`BusPerception.objects` call, so a robot client whose tree never looks asks the bus for
nothing (and the first look finds the list the tracker publishes next, within a second).
"""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Callable

from cyborg.bus import Node
from cyborg.bus.msgs.cyborg_msgs.msg import TrackedObjects
from cyborg.bus.msgs.geometry_msgs.msg import Twist, Vector3
from cyborg.bus.msgs.std_msgs.msg import String
from cyborg.interfaces import perception, robot
from cyborg.robot.perceiving import SeenObject

STALE_AFTER = 3.0
"""Wall-clock seconds after which a list that was not renewed counts as empty (the tracker
publishes at least once a second)."""


def _seconds(stamp: object) -> float:
    return float(stamp.sec) + float(stamp.nanosec) * 1e-9  # type: ignore[attr-defined]


def seen_objects(message: TrackedObjects) -> list[SeenObject]:
    """The objects of an ``objects`` message, their ages as of its stamp."""
    now = _seconds(message.header.stamp)
    return [SeenObject(int(item.id), str(item.label), float(item.confidence),
                       float(item.position.x), float(item.position.y), float(item.velocity.x),
                       float(item.velocity.y), max(0.0, now - _seconds(item.last_seen)),
                       int(item.times_seen), float(item.distance), float(item.bearing))
            for item in message.objects
            if math.isfinite(item.position.x) and math.isfinite(item.position.y)]


class BusPerception:
    """The ``objects``, ``say`` and ``cmd_vel`` endpoints of the robot under ``namespace``."""

    def __init__(self, node: Node, namespace: str, *,
                 wall: Callable[[], float] = time.monotonic) -> None:
        self.node, self.namespace, self.wall = node, namespace, wall
        self._say = perception.SAY.publisher(node, namespace)
        self._drive = robot.CMD_VEL.publisher(node, namespace)
        self._objects: list[SeenObject] = []
        self._received = -math.inf
        self._lock = threading.Lock()
        self._subscribed = False

    def _on_objects(self, message: TrackedObjects) -> None:
        objects = seen_objects(message)
        with self._lock:
            self._objects, self._received = objects, self.wall()

    def objects(self) -> list[SeenObject]:
        """The latest list (subscribing on the first call); empty when stale."""
        with self._lock:
            if not self._subscribed:
                self._subscribed = True
                perception.OBJECTS.subscription(self.node, self._on_objects, self.namespace)
            if self.wall() - self._received > STALE_AFTER:
                return []
            return list(self._objects)

    def say(self, text: str) -> None:
        """Publishes ``text`` on ``say``."""
        self._say.publish(String(data=text))

    def drive(self, linear: float, angular: float) -> None:
        """Publishes one ``cmd_vel`` command (the robot clamps it to its limits)."""
        self._drive.publish(Twist(linear=Vector3(x=float(linear), y=0.0, z=0.0),
                                  angular=Vector3(x=0.0, y=0.0, z=float(angular))))
