"""What the robot's detector saw, placed on the map for the page: small JSON, checked.

The detector (:mod:`cyborg.interfaces.detector`) publishes, per camera image, the objects it
found: ``detections`` (vision_msgs/Detection2DArray, ROS 2's message: the class in
``results[0].hypothesis.class_id``, the score, and the distance along the camera's axis in
``results[0].pose.pose.position.z``) and the 2018 ``predictions`` (cyborg_msgs/Predictions:
``label``, ``confidence``, ``distance``). Both carry the distance in metres, NaN when unknown,
and the box in image pixels; neither says how wide the image is or what the camera's field of
view is, and no camera_info is published.

So each object is placed **straight ahead of the camera, at its distance**: at
``mount ⊕ (distance, 0)`` in the robot's frame, where ``mount`` is where the camera sits on the
robot (the ``/tf_static`` transform to the message's ``frame_id``, chained up to the robot's
frame, as for the laser; without one the robot's centre facing forward), and then through the
robot's pose into the map. An object off to the side of the image is thus drawn on the camera's
axis at the right distance: the map shows how far, not which way within the camera's view.

:func:`detections_wire` and :func:`predictions_wire` read a message into ``(objects, frame,
warnings)``, each object ``{"label", "score", "r"}``; :func:`place` turns them into what the page
gets, ``{"label", "score", "p": [x, y]}`` (m, 1 cm). Objects whose distance is unknown (NaN) are
left out silently (the detector's way of saying "no depth"); a distance that is infinite,
negative or beyond :data:`DISTANCE_LIMIT`, or a score that is not a number, leaves that object
out with a warning; beyond :data:`DETECTION_LIMIT` objects in one message the rest are dropped,
with a warning. None of them raises on any value a message can carry.
"""

from __future__ import annotations

import math
from typing import Any

from cyborg.bus.msgs.cyborg_msgs.msg import Predictions
from cyborg.bus.msgs.vision_msgs.msg import Detection2DArray
from cyborg.monitor.robot_wire import Mount, Warnings, clip_text

DETECTION_LIMIT = 200
"""Most objects of one message that are placed (the detector keeps a few dozen at most)."""
DISTANCE_LIMIT = 100.0
"""Farthest an object may be from the camera to be placed, in metres."""
LABEL_LIMIT = 60
"""Longest class label passed on, in characters."""

Found = dict[str, Any]
"""One object as read: ``{"label", "score", "r"}`` (score 0-1, distance in m)."""


def detections_wire(message: Detection2DArray) -> tuple[list[Found], str, Warnings]:
    """The objects of a ``detections`` message, its camera frame, and warnings."""
    items = message.detections
    warnings = _count_warning(len(items))
    found: list[Found] = []
    for index, item in enumerate(items[:DETECTION_LIMIT]):
        if not item.results:
            warnings.append(f"detections: object {index} has no result; left out")
            continue
        result = item.results[0]
        _add(found, warnings, index, result.hypothesis.class_id, result.hypothesis.score,
             result.pose.pose.position.z)
    frame, _clipped = clip_text(message.header.frame_id)
    return found, frame, _summarised(warnings)


def predictions_wire(message: Predictions) -> tuple[list[Found], str, Warnings]:
    """The objects of a 2018 ``predictions`` message, its camera frame, and warnings."""
    items = message.predictions
    warnings = _count_warning(len(items))
    found: list[Found] = []
    for index, item in enumerate(items[:DETECTION_LIMIT]):
        _add(found, warnings, index, item.label, item.confidence, item.distance)
    frame, _clipped = clip_text(message.header.frame_id)
    return found, frame, _summarised(warnings)


def place(found: list[Found], pose: list[float], mount: Mount | None) -> list[dict[str, Any]]:
    """The objects on the map, each ``{"label", "score", "p": [x, y]}`` (m, 1 cm).

    Each lies straight ahead of the camera, at its distance; the camera sits at ``mount`` on
    the robot (its centre facing forward when None), the robot at ``pose`` (``[x, y, θ]``).
    """
    mx, my, mtheta = mount if mount is not None else (0.0, 0.0, 0.0)
    x, y, theta = pose
    cos, sin = math.cos(theta), math.sin(theta)
    camera_x, camera_y = x + cos * mx - sin * my, y + sin * mx + cos * my
    heading = theta + mtheta
    return [{"label": item["label"], "score": item["score"],
             "p": [round(camera_x + item["r"] * math.cos(heading), 2),
                   round(camera_y + item["r"] * math.sin(heading), 2)]} for item in found]


def _add(found: list[Found], warnings: Warnings, index: int, label: str, score: float,
         distance: float) -> None:
    r, confidence = float(distance), float(score)
    if math.isnan(r):
        return  # unknown distance: nothing to place
    if not 0.0 <= r <= DISTANCE_LIMIT:
        warnings.append(f"detections: object {index} at {r:.6g} m, not 0 to "
                        f"{DISTANCE_LIMIT:g} m; left out")
        return
    if not math.isfinite(confidence):
        warnings.append(f"detections: object {index}'s score is {confidence:.6g}; left out")
        return
    text, _clipped = clip_text(label, LABEL_LIMIT)
    found.append({"label": text, "score": round(min(1.0, max(0.0, confidence)), 2),
                  "r": r})


def _count_warning(count: int) -> Warnings:
    if count <= DETECTION_LIMIT:
        return []
    return [f"detections: {count:,} objects in one message; the first {DETECTION_LIMIT} "
            "placed"]


def _summarised(warnings: Warnings, shown: int = 3) -> Warnings:
    """At most ``shown`` warnings of one message, and how many more there were."""
    if len(warnings) <= shown:
        return warnings
    return [*warnings[:shown], f"detections: and {len(warnings) - shown:,} more objects "
                               "left out"]
