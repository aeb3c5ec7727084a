"""The tracker's objects as the ``objects`` topic carries them (cyborg_msgs/TrackedObjects).

:func:`objects_message` writes the list the tracker keeps into the message of
:data:`cyborg.interfaces.perception.OBJECTS`: the ``map`` frame, the stamp of the newest
detections, and per object its confidence *as of that stamp* (decayed while unseen), so a reader
need not know the tracker's settings. :func:`seconds_of` and :func:`time_of` convert stamps.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from typing import Any

from cyborg.bus.msgs.builtin_interfaces.msg import Time
from cyborg.bus.msgs.cyborg_msgs.msg import TrackedObject as TrackedObjectMessage
from cyborg.bus.msgs.cyborg_msgs.msg import TrackedObjects
from cyborg.bus.msgs.geometry_msgs.msg import Point, Vector3
from cyborg.bus.msgs.std_msgs.msg import Header
from cyborg.interfaces.perception import MAP_FRAME
from cyborg.perception.tracker import TrackedObject


def time_of(seconds: float) -> Time:
    """A ``builtin_interfaces/Time`` of ``seconds`` (0 for anything negative or not finite)."""
    if not (math.isfinite(seconds) and seconds > 0):
        return Time(sec=0, nanosec=0)
    whole = int(seconds)
    return Time(sec=whole, nanosec=min(int((seconds - whole) * 1e9), 999_999_999))


def seconds_of(stamp: Any) -> float:
    """The seconds of a ``builtin_interfaces/Time``."""
    return float(stamp.sec) + float(stamp.nanosec) * 1e-9


def objects_message(objects: Iterable[TrackedObject], now: float) -> TrackedObjects:
    """The ``objects`` message of ``objects`` as of ``now`` (seconds)."""
    return TrackedObjects(
        header=Header(stamp=time_of(now), frame_id=MAP_FRAME),
        objects=[TrackedObjectMessage(
            id=item.id, label=item.label, confidence=item.confidence_at(now),
            position=Point(x=item.x, y=item.y, z=0.0),
            velocity=Vector3(x=item.vx, y=item.vy, z=0.0), last_seen=time_of(item.last_seen),
            times_seen=item.times_seen, distance=item.distance, bearing=item.bearing)
            for item in objects])
