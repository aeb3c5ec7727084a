"""The objects a robot's tracker follows, as the page's map gets them: small JSON, checked.

The tracker (:mod:`cyborg.perception`) publishes the robot's ``objects``
(:data:`cyborg.interfaces.perception.OBJECTS`, cyborg_msgs/TrackedObjects): in the ``map``
frame, as of the header's stamp, each object with its id, label, confidence, position,
velocity, the stamp it was last seen at and how often it was seen. Unlike the detector's raw
detections (:mod:`cyborg.monitor.detection_wire`), these are already on the map: the monitor
only checks them and makes them small.

:func:`objects_wire` reads one message into ``(objects, warnings)``; each object is::

    {"id": 7, "label": "person", "x": 3.21, "y": -1.05, "vx": 0.8, "vy": 0.0,
     "conf": 0.78, "age": 0.4, "seen": 12}

``x``, ``y`` in m (1 cm), ``vx``, ``vy`` in m/s (1 cm/s), ``conf`` 0-1 (0.01), ``age`` the
seconds since it was last seen, on the message's own stamp (0.01 s, 0 to :data:`AGE_LIMIT`),
``seen`` the number of frames it was seen in. The topic is bus input anyone may publish, so:

* a message in a frame other than ``map`` (or a fleet's ``robot1/map``) is refused whole;
* an object whose position is not finite or more than
  :data:`~cyborg.monitor.robot_wire.WORLD_LIMIT` m from the origin, or whose confidence is not
  a number, is left out; a repeated id keeps its first object;
* a velocity that is not finite or faster than :data:`SPEED_LIMIT` becomes 0 (the object is
  drawn, without an arrow); a confidence outside 0-1 is clamped;
* labels are cut to :data:`LABEL_LIMIT` characters, and beyond :data:`OBJECT_LIMIT` objects
  the rest of the message is not read.

Each of these is a warning (at most a few per message, then how many more). Nothing here
raises on any value a message can carry.
"""

from __future__ import annotations

import math
from typing import Any

from cyborg.bus.msgs.cyborg_msgs.msg import TrackedObject, TrackedObjects
from cyborg.interfaces.perception import MAP_FRAME
from cyborg.monitor.robot_wire import WORLD_LIMIT, Warnings, clip_text

OBJECT_LIMIT = 200
"""Most objects of one message that are read and sent (the tracker keeps at most 256)."""
LABEL_LIMIT = 60
"""Longest label passed on, in characters."""
SPEED_LIMIT = 20.0
"""Fastest velocity component drawn, m/s (the tracker caps speeds at 3 m/s)."""
AGE_LIMIT = 3600.0
"""Largest age sent, s (the tracker forgets an object after 5 s unseen)."""
WARNINGS_SHOWN = 3
"""Warnings of one message given one by one; the rest are counted in one more."""

TrackedItem = dict[str, Any]
"""One object as the page gets it (see the module docstring)."""


def objects_wire(message: TrackedObjects) -> tuple[list[TrackedItem] | None, Warnings]:
    """The objects of one ``objects`` message, checked; None when it is refused whole."""
    frame, _clipped = clip_text(message.header.frame_id, 100)
    if frame.rsplit("/", 1)[-1] != MAP_FRAME:
        return None, [f"objects: frame {frame!r}, not {MAP_FRAME!r}; message ignored"]
    stamp = _seconds(message.header.stamp)
    items = message.objects
    warnings: Warnings = []
    if len(items) > OBJECT_LIMIT:
        warnings.append(f"objects: {len(items):,} objects in one message; the first "
                        f"{OBJECT_LIMIT} drawn")
    found: list[TrackedItem] = []
    ids: set[int] = set()
    for index, item in enumerate(items[:OBJECT_LIMIT]):
        read = _object(item, index, stamp, warnings)
        if read is None:
            continue
        if read["id"] in ids:
            warnings.append(f"objects: object {index} repeats id {read['id']}; left out")
            continue
        ids.add(read["id"])
        found.append(read)
    return found, _summarised(warnings)


def _object(item: TrackedObject, index: int, stamp: float,
            warnings: Warnings) -> TrackedItem | None:
    x, y = float(item.position.x), float(item.position.y)
    if not (math.isfinite(x) and math.isfinite(y) and math.hypot(x, y) <= WORLD_LIMIT):
        warnings.append(f"objects: object {index} at ({x:.6g}, {y:.6g}), not a place on the "
                        "map; left out")
        return None
    confidence = float(item.confidence)
    if math.isnan(confidence):
        warnings.append(f"objects: object {index}'s confidence is nan; left out")
        return None
    vx, vy = float(item.velocity.x), float(item.velocity.y)
    if not (math.isfinite(vx) and math.isfinite(vy)
            and abs(vx) <= SPEED_LIMIT and abs(vy) <= SPEED_LIMIT):
        warnings.append(f"objects: object {index}'s velocity ({vx:.6g}, {vy:.6g}) is not a "
                        "speed; drawn at rest")
        vx = vy = 0.0
    label, _clipped = clip_text(item.label, LABEL_LIMIT)
    age = min(max(stamp - _seconds(item.last_seen), 0.0), AGE_LIMIT)
    return {"id": int(item.id), "label": label, "x": round(x, 2), "y": round(y, 2),
            "vx": round(vx, 2), "vy": round(vy, 2),
            "conf": round(min(1.0, max(0.0, confidence)), 2), "age": round(age, 2),
            "seen": int(item.times_seen)}


def _seconds(stamp: Any) -> float:
    """A ``builtin_interfaces/Time`` in seconds (whatever its nanoseconds say)."""
    return float(stamp.sec) + float(stamp.nanosec) * 1e-9


def _summarised(warnings: Warnings) -> Warnings:
    """At most :data:`WARNINGS_SHOWN` warnings of one message, and how many more there were."""
    if len(warnings) <= WARNINGS_SHOWN + 1:
        return warnings
    return [*warnings[:WARNINGS_SHOWN],
            f"objects: and {len(warnings) - WARNINGS_SHOWN:,} more warnings"]
