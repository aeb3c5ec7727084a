"""The simulated camera on the bus: detections published exactly as the detector node does.

Under the robot's detector namespace (:func:`cyborg.interfaces.detector.detector_of_robot`:
``/cyborg/detector`` for ``/cyborg``) it publishes, every camera frame of simulated time
(:attr:`~cyborg.sim.camera.CameraSpec.rate`), the detector's topics of
:mod:`cyborg.interfaces.detector`, built by the same functions
(:mod:`cyborg.interfaces.detection_messages`):

=====================  ==================================  ==================================
``predictions``        cyborg_msgs/Predictions             latched; label, confidence,
                                                           distance (m), 4-corner polygon
``detections``         vision_msgs/Detection2DArray        box centre and size, class and
                                                           score, distance in ``position.z``
``detection_image``    sensor_msgs/Image (bgr8)            only with ``image`` on and a
                                                           subscriber: the boxes drawn on a
                                                           plain background
=====================  ==================================  ==================================

The image header (``image_header``, each detection's header) carries the frame's simulated
time and the camera's frame (:data:`~cyborg.interfaces.detector.CAMERA_FRAME`), and the
predictions' own header is stamped with the same simulated time, as a detector under
``use_sim_time`` stamps it. Like the detector node it skips frames while nobody subscribes
(counted in ``skipped``), and it publishes at most ``max_publish_rate`` frames per wall-clock
second, so a simulation running hundreds of times faster than real time does not flood the bus.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable

import numpy as np

from cyborg.bus import Node
from cyborg.bus.msgs.builtin_interfaces.msg import Time
from cyborg.bus.msgs.sensor_msgs.msg import Image
from cyborg.bus.msgs.std_msgs.msg import Header
from cyborg.interfaces.detection_messages import detection_array_message, predictions_message
from cyborg.interfaces.detector import CAMERA_FRAME, DETECTION_IMAGE, DETECTIONS, PREDICTIONS
from cyborg.sim.camera import CameraSpec, SeenObject, SimCamera
from cyborg.sim.loop import RobotLoop
from cyborg.sim.sights import Sights
from cyborg.sim.simulator import Simulator

MAX_PUBLISH_RATE = 100.0
"""Frames per wall-clock second the camera publishes at most (all of them up to 10x speed)."""


class SimCameraNode:
    """Publishes a simulated camera's detections on ``node``; see the module doc.

    ``sights`` gives what there is to see around a simulator at a frame (``loop``'s thread,
    lock held); the camera sees the walls of the simulator's laser grid (its map's);
    ``image``: whether to draw ``detection_image`` (when someone subscribes); ``clock`` gives
    wall-clock seconds for the publishing limit.
    """

    def __init__(self, node: Node, loop: RobotLoop, camera: SimCamera,
                 sights: Callable[[Simulator], Sights], *, image: bool = False,
                 frame_id: str = CAMERA_FRAME, max_publish_rate: float = MAX_PUBLISH_RATE,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self.node, self.camera, self.sights = node, camera, sights
        self.draw, self.frame_id, self.clock = image, frame_id, clock
        self._min_period = 1.0 / max_publish_rate
        self._published_at = -math.inf
        self._due = 0.0
        self._walls: object = None
        self.frames = self.skipped = 0
        self.last: list[SeenObject] = []
        self.predictions = PREDICTIONS.publisher(node)
        self.detections = DETECTIONS.publisher(node)
        self.image = DETECTION_IMAGE.publisher(node)
        loop.on_sensor.append(self._frame)

    def watched(self) -> bool:
        """Whether any output has a subscriber; frames are skipped (and counted) while none has."""
        return any(publisher.subscription_count() > 0
                   for publisher in (self.predictions, self.detections, self.image))

    def _frame(self, sim: Simulator) -> None:
        if self.node.destroyed or sim.time + 1e-9 < self._due:
            return
        self._due = max(self._due + 1.0 / self.camera.spec.rate, sim.time)
        if not self.watched():
            self.skipped += 1
            return
        now = self.clock()
        if now - self._published_at < self._min_period:
            return
        self._published_at = now
        pose, laser = sim.pose, sim.laser
        if laser.occupied is not self._walls:
            self._walls = laser.occupied
            self.camera.look_at(laser.occupied, laser.origin, laser.resolution)
        self.last = self.camera.observe(pose.x, pose.y, pose.theta, self.sights(sim),
                                        sim.others)
        self.frames += 1
        stamp_ns = round(sim.time * 1e9)
        header = Header(stamp=Time(sec=stamp_ns // 1_000_000_000,
                                   nanosec=stamp_ns % 1_000_000_000), frame_id=self.frame_id)
        try:
            self.predictions.publish(predictions_message(self.last, header, stamp_ns))
            self.detections.publish(detection_array_message(self.last, header))
            if self.draw and self.image.subscription_count() > 0:
                self.image.publish(image_message(drawn(self.last, self.camera.spec), header))
        except RuntimeError:
            if not self.node.destroyed:  # the node went while publishing: nothing to say
                raise


BACKGROUND = ((96, 88, 80), (60, 60, 60))
"""BGR colours of the drawn image's upper half (walls) and lower half (floor)."""
BOX = (0, 200, 0)
"""BGR colour of a detection's box (green, as the detector draws it)."""


def drawn(seen: list[SeenObject], spec: CameraSpec, thickness: int = 2) -> np.ndarray:
    """A ``spec``-sized BGR picture with each detection's box drawn on a plain background."""
    picture = np.empty((spec.height, spec.width, 3), np.uint8)
    picture[: spec.height // 2] = BACKGROUND[0]
    picture[spec.height // 2:] = BACKGROUND[1]
    for item in seen:
        x1, y1, x2, y2 = (round(value) for value in item.box)
        x2, y2 = min(x2, spec.width), min(y2, spec.height)
        picture[y1:min(y1 + thickness, y2), x1:x2] = BOX
        picture[max(y2 - thickness, y1):y2, x1:x2] = BOX
        picture[y1:y2, x1:min(x1 + thickness, x2)] = BOX
        picture[y1:y2, max(x2 - thickness, x1):x2] = BOX
    return picture


def image_message(picture: np.ndarray, header: Header) -> Image:
    """A ``bgr8`` ``sensor_msgs/Image`` of ``picture`` (H x W x 3 uint8)."""
    height, width = picture.shape[:2]
    return Image(header=header, height=height, width=width, encoding="bgr8", is_bigendian=0,
                 step=width * 3, data=np.ascontiguousarray(picture).reshape(-1))
