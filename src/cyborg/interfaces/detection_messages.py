"""Detections as bus messages: 2018's ``cyborg_msgs/Predictions``, ROS 2's ``Detection2DArray``.

Both producers of detections build their messages here, so that a consumer cannot tell them
apart: the detector node on camera frames (:mod:`cyborg.vision.detector_node`) and the
simulated camera (:mod:`cyborg.sim.camera_node`). Each takes any object with a ``label``, a
``confidence``, a ``box`` (``x1, y1, x2, y2`` in image pixels) and a ``distance``
(:class:`BoxedObject`).

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
from typing import Any, Protocol

import numpy as np

from cyborg.bus.msgs.builtin_interfaces.msg import Time
from cyborg.bus.msgs.cyborg_msgs.msg import Prediction, Predictions
from cyborg.bus.msgs.geometry_msgs.msg import (
    Point,
    Point32,
    Polygon,
    Pose,
    PoseWithCovariance,
    Quaternion,
)
from cyborg.bus.msgs.std_msgs.msg import Header
from cyborg.bus.msgs.vision_msgs.msg import (
    BoundingBox2D,
    Detection2D,
    Detection2DArray,
    ObjectHypothesis,
    ObjectHypothesisWithPose,
    Point2D,
    Pose2D,
)


class BoxedObject(Protocol):
    """What a message needs of one detection: class, confidence, box in pixels, distance (m)."""

    @property
    def label(self) -> str:
        """The class name (``person``)."""

    @property
    def confidence(self) -> float:
        """The detector's confidence, 0..1."""

    @property
    def box(self) -> tuple[float, float, float, float]:
        """``x1, y1, x2, y2`` in image pixels."""

    @property
    def distance(self) -> float:
        """Metres along the camera's optical axis; NaN when unknown."""


def corners(box: tuple[float, float, float, float]) -> tuple[tuple[float, float], ...]:
    """Top-left, top-right, bottom-right, bottom-left of ``box`` (the 2018 polygon order)."""
    x1, y1, x2, y2 = box
    return (x1, y1), (x2, y1), (x2, y2), (x1, y2)


def _copy_header(header: Any) -> Header:
    return Header(stamp=Time(sec=int(header.stamp.sec), nanosec=int(header.stamp.nanosec)),
                  frame_id=str(header.frame_id))


def predictions_message(detections: Sequence[BoxedObject],
                        image_header: Any, now_ns: int) -> Predictions:
    """``cyborg_msgs/msg/Predictions`` for one image, made at ``now_ns`` (nanoseconds)."""
    return Predictions(
        header=Header(stamp=Time(sec=now_ns // 1_000_000_000, nanosec=now_ns % 1_000_000_000),
                      frame_id=str(image_header.frame_id)),
        image_header=_copy_header(image_header),
        predictions=[Prediction(
            label=d.label, confidence=float(d.confidence), distance=float(d.distance),
            bounding_box=Polygon(points=[Point32(x=float(x), y=float(y), z=0.0)
                                         for x, y in corners(d.box)]))
            for d in detections])


def detection_array_message(detections: Sequence[BoxedObject],
                            image_header: Any) -> Detection2DArray:
    """``vision_msgs/msg/Detection2DArray`` for one image."""
    items = []
    for index, d in enumerate(detections):
        x1, y1, x2, y2 = d.box
        pose = Pose(position=Point(x=0.0, y=0.0, z=float(d.distance)),
                    orientation=Quaternion(x=0.0, y=0.0, z=0.0, w=1.0))
        items.append(Detection2D(
            header=_copy_header(image_header),
            results=[ObjectHypothesisWithPose(
                hypothesis=ObjectHypothesis(class_id=d.label, score=float(d.confidence)),
                pose=PoseWithCovariance(pose=pose, covariance=np.zeros(36, np.float64)))],
            bbox=BoundingBox2D(center=Pose2D(position=Point2D(x=(x1 + x2) / 2, y=(y1 + y2) / 2),
                                             theta=0.0),
                               size_x=x2 - x1, size_y=y2 - y1),
            id=str(index)))
    return Detection2DArray(header=_copy_header(image_header), detections=items)
