"""Detections as bus messages: the 2018 ``cyborg_msgs/Predictions`` and ROS 2's
``vision_msgs/Detection2DArray``.

``Predictions`` keeps the 2018 fields: a header (when the detections were made), the image's
header, and per object the label, confidence, distance (metres; NaN when unknown) and a
polygon of the box's four corners (top-left, top-right, bottom-right, bottom-left).

``Detection2DArray`` is what ROS 2 tools understand: per object a ``Detection2D`` with the
image's header, one hypothesis (``class_id`` = the label, ``score``), the box as centre and
size, and the distance along the camera's optical axis in ``results[0].pose.pose.position.z``
(NaN when unknown).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from cyborg.bus import MessageTypes, new_message
from cyborg.vision.detector import Detection


def _header(header: Any) -> dict[str, Any]:
    return {"stamp": {"sec": int(header.stamp.sec), "nanosec": int(header.stamp.nanosec)},
            "frame_id": str(header.frame_id)}


def predictions_message(types: MessageTypes, detections: Sequence[Detection],
                        image_header: Any, now_ns: int) -> Any:
    """``cyborg_msgs/msg/Predictions`` for one image."""
    return new_message(types, "cyborg_msgs/msg/Predictions", {
        "header": {"stamp": {"sec": now_ns // 1_000_000_000,
                             "nanosec": now_ns % 1_000_000_000},
                   "frame_id": str(image_header.frame_id)},
        "image_header": _header(image_header),
        "predictions": [{
            "label": detection.label, "confidence": detection.confidence,
            "distance": detection.distance,
            "bounding_box": {"points": [{"x": x, "y": y, "z": 0.0}
                                        for x, y in detection.corners]}}
            for detection in detections]})


def detection_array_message(types: MessageTypes, detections: Sequence[Detection],
                            image_header: Any) -> Any:
    """``vision_msgs/msg/Detection2DArray`` for one image."""
    header = _header(image_header)
    items = []
    for index, detection in enumerate(detections):
        x1, y1, x2, y2 = detection.box
        items.append({
            "header": header,
            "results": [{"hypothesis": {"class_id": detection.label,
                                        "score": detection.confidence},
                         "pose": {"pose": {"position": {"z": detection.distance},
                                           "orientation": {"w": 1.0}}}}],
            "bbox": {"center": {"position": {"x": (x1 + x2) / 2, "y": (y1 + y2) / 2}},
                     "size_x": x2 - x1, "size_y": y2 - y1},
            "id": str(index)})
    return new_message(types, "vision_msgs/msg/Detection2DArray",
                       {"header": header, "detections": items})
