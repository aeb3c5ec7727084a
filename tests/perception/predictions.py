"""Building cyborg_msgs/Predictions as a detector publishes them, for the tracker's tests."""

from __future__ import annotations

import math

from cyborg.bus.msgs.builtin_interfaces.msg import Time
from cyborg.bus.msgs.cyborg_msgs.msg import Prediction, Predictions
from cyborg.bus.msgs.geometry_msgs.msg import Point32, Polygon
from cyborg.bus.msgs.std_msgs.msg import Header
from cyborg.interfaces.perception import CAMERA


def box(column: float, half_width: float = 20.0) -> Polygon:
    """A box centred on ``column``, corners TL, TR, BR, BL as the detector writes them."""
    left, right = column - half_width, column + half_width
    return Polygon(points=[Point32(x=left, y=100.0, z=0.0), Point32(x=right, y=100.0, z=0.0),
                           Point32(x=right, y=300.0, z=0.0), Point32(x=left, y=300.0, z=0.0)])


def prediction(label: str = "person", distance: float = 2.0, bearing: float = 0.0,
               confidence: float = 0.9, column: float | None = None) -> Prediction:
    """A prediction of ``label`` seen at ``bearing`` (radians, left positive) and ``distance``."""
    centre = CAMERA.column(bearing) if column is None else column
    return Prediction(label=label, confidence=confidence, distance=distance,
                      bounding_box=box(centre))


def predictions(items: list[Prediction], stamp: float = 0.0) -> Predictions:
    """A Predictions message of ``items`` stamped ``stamp`` seconds."""
    whole = math.floor(stamp)
    time = Time(sec=whole, nanosec=round((stamp - whole) * 1e9))
    header = Header(stamp=time, frame_id="camera_left")
    return Predictions(header=header, image_header=header, predictions=items)
