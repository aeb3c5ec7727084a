"""The camera's and the detector's interfaces, between them and their users.

What :class:`~cyborg.vision.CameraNode` (or a ZED driver on the robot) publishes, what
:class:`~cyborg.vision.DetectorNode` reads and publishes, and what their consumers subscribe to.

Camera, under its namespace (:data:`CAMERA_NAMESPACE`, ``/cyborg/camera`` by default):

============================  ==========================  ========================================
topic                         type                        content
============================  ==========================  ========================================
``left/image_raw``            sensor_msgs/Image           the colour image (``bgr8``)
``right/image_raw``           sensor_msgs/Image           the right image of a stereo camera
``depth/depth_registered``    sensor_msgs/Image           depth in metres (``32FC1``)
============================  ==========================  ========================================

all stamped alike, so that a detector pairs them by exact stamp (:data:`CAMERA_STREAMS`).

Detector, under its namespace (:data:`DETECTOR_NAMESPACE`, ``/cyborg/detector`` by default):

============================  ==========================  ========================================
``predictions``               cyborg_msgs/Predictions     latched: the 2018 message
``detections``                vision_msgs/Detection2DArray  ROS 2's standard message
``detection_image``           sensor_msgs/Image           the image with boxes and labels
============================  ==========================  ========================================

The detector reads the camera topics named by its parameters, by default
:data:`DEFAULT_IMAGE_TOPIC` and :data:`DEFAULT_DEPTH_TOPIC`.
"""

from __future__ import annotations

from cyborg.bus.msgs.cyborg_msgs.msg import Predictions
from cyborg.bus.msgs.sensor_msgs.msg import Image
from cyborg.bus.msgs.vision_msgs.msg import Detection2DArray
from cyborg.interfaces.contract import Topic

CAMERA_NAMESPACE = "/cyborg/camera"
DETECTOR_NAMESPACE = "/cyborg/detector"

# ---------------------------------------------------------------------- the camera
IMAGE = Topic("left/image_raw", Image, depth=2)
RIGHT_IMAGE = Topic("right/image_raw", Image, depth=2)
DEPTH = Topic("depth/depth_registered", Image, depth=2)
CAMERA_STREAMS: dict[str, Topic[Image]] = {"image": IMAGE, "depth": DEPTH, "right": RIGHT_IMAGE}
"""The camera's topics by the stream name a detector pairs them under."""

DEFAULT_IMAGE_TOPIC = IMAGE.full_name(CAMERA_NAMESPACE)
DEFAULT_DEPTH_TOPIC = DEPTH.full_name(CAMERA_NAMESPACE)

CAMERA_FRAME = "camera_left"
"""The frame of the camera's images, and so of the detections' headers (the ZED's left eye)."""

# ---------------------------------------------------------------------- the detector
PREDICTIONS = Topic("predictions", Predictions, latched=True)
DETECTIONS = Topic("detections", Detection2DArray, depth=5)
DETECTION_IMAGE = Topic("detection_image", Image, depth=1)
DETECTOR_TOPICS: tuple[Topic, ...] = (PREDICTIONS, DETECTIONS, DETECTION_IMAGE)

# ---------------------------------------------------------------------- the detector's parameters
CONFIDENCE_THRESHOLD = "confidence_threshold"
"""Detections below this confidence (0..1) are dropped; settable at runtime."""
IOU_THRESHOLD = "iou_threshold"
"""Overlap above which boxes of one class merge (0..1); settable at runtime."""
CLASSES = "classes"
"""Labels to keep (empty: every class); settable at runtime."""

# ---------------------------------------------------------------------- where it runs
DETECTOR_UNDER_ROBOT = "/detector"
"""Where a robot's detector lives under the robot's namespace (``/cyborg`` →
``/cyborg/detector``, :data:`DETECTOR_NAMESPACE`), as ``cyborg up`` places it."""


def detector_of_robot(namespace: str) -> str:
    """The namespace of the detector that looks out of the robot under ``namespace``.

    By the convention of :data:`DETECTOR_UNDER_ROBOT`: ``/robot1`` → ``/robot1/detector``.
    """
    return namespace.rstrip("/") + DETECTOR_UNDER_ROBOT
