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

import numpy as np

from cyborg.bus import MessageTypes
from cyborg.interfaces.detector import DETECTIONS, PREDICTIONS
from cyborg.vision.detector import Detection


class _Classes:
    """The message classes used here, looked up once per type registry."""

    def __init__(self, types: MessageTypes) -> None:
        get = types.message_class
        self.time, self.header = get("builtin_interfaces/msg/Time"), get("std_msgs/msg/Header")
        self.point32, self.polygon = get("geometry_msgs/msg/Point32"), \
            get("geometry_msgs/msg/Polygon")
        self.prediction = get("cyborg_msgs/msg/Prediction")
        self.predictions = get(PREDICTIONS.type_name)
        self.point, self.quaternion = get("geometry_msgs/msg/Point"), \
            get("geometry_msgs/msg/Quaternion")
        self.pose = get("geometry_msgs/msg/Pose")
        self.pose_cov = get("geometry_msgs/msg/PoseWithCovariance")
        self.hypothesis = get("vision_msgs/msg/ObjectHypothesis")
        self.with_pose = get("vision_msgs/msg/ObjectHypothesisWithPose")
        self.point2d, self.pose2d = get("vision_msgs/msg/Point2D"), get("vision_msgs/msg/Pose2D")
        self.bbox = get("vision_msgs/msg/BoundingBox2D")
        self.detection = get("vision_msgs/msg/Detection2D")
        self.array = get(DETECTIONS.type_name)


_CACHE: dict[int, _Classes] = {}


def _classes(types: MessageTypes) -> _Classes:
    found = _CACHE.get(id(types))
    if found is None:
        found = _CACHE[id(types)] = _Classes(types)
    return found


def _copy_header(c: _Classes, header: Any) -> Any:
    return c.header(stamp=c.time(sec=int(header.stamp.sec), nanosec=int(header.stamp.nanosec)),
                    frame_id=str(header.frame_id))


def predictions_message(types: MessageTypes, detections: Sequence[Detection],
                        image_header: Any, now_ns: int) -> Any:
    """``cyborg_msgs/msg/Predictions`` for one image."""
    c = _classes(types)
    return c.predictions(
        header=c.header(stamp=c.time(sec=now_ns // 1_000_000_000,
                                     nanosec=now_ns % 1_000_000_000),
                        frame_id=str(image_header.frame_id)),
        image_header=_copy_header(c, image_header),
        predictions=[c.prediction(
            label=d.label, confidence=float(d.confidence), distance=float(d.distance),
            bounding_box=c.polygon(points=[c.point32(x=float(x), y=float(y), z=0.0)
                                           for x, y in d.corners]))
            for d in detections])


def detection_array_message(types: MessageTypes, detections: Sequence[Detection],
                            image_header: Any) -> Any:
    """``vision_msgs/msg/Detection2DArray`` for one image."""
    c = _classes(types)
    items = []
    for index, d in enumerate(detections):
        x1, y1, x2, y2 = d.box
        pose = c.pose(position=c.point(x=0.0, y=0.0, z=float(d.distance)),
                      orientation=c.quaternion(x=0.0, y=0.0, z=0.0, w=1.0))
        items.append(c.detection(
            header=_copy_header(c, image_header),
            results=[c.with_pose(
                hypothesis=c.hypothesis(class_id=d.label, score=float(d.confidence)),
                pose=c.pose_cov(pose=pose, covariance=np.zeros(36, np.float64)))],
            bbox=c.bbox(center=c.pose2d(position=c.point2d(x=(x1 + x2) / 2, y=(y1 + y2) / 2),
                                        theta=0.0),
                        size_x=x2 - x1, size_y=y2 - y1),
            id=str(index)))
    return c.array(header=_copy_header(c, image_header), detections=items)
