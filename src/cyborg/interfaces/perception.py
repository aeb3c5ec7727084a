"""What a robot makes of its detections: tracked objects on the map, its camera, its voice.

The tracker (:mod:`cyborg.perception`) turns the detector's predictions
(:mod:`cyborg.interfaces.detector`) into objects on the map; the tree's nodes
(``ObjectDetected``, ``FaceObject``, ``Say`` ... in :mod:`cyborg.robot`), the planner and the
monitor's map read them. Under the robot's namespace (:data:`~cyborg.interfaces.robot.NAMESPACE`,
``/cyborg`` by default):

============  ===========================  =================================================
topic         type                         content
============  ===========================  =================================================
``objects``   cyborg_msgs/TrackedObjects   the objects followed, in the ``map`` frame, after
                                           every frame of predictions and at least once a
                                           second (stamp: the newest detections); not
                                           latched, depth 2: only the newest list matters
``say``       std_msgs/String              a sentence for the robot to speak, as written
                                           (a speech node says it; nothing is queued here)
============  ===========================  =================================================

The 2018 system had no speech topic; ``say`` follows ROS's ``std_msgs/String`` convention for a
text-to-speech input, so any speech node that subscribes to a string works.

**The camera model.** A detection's box centre column ``u`` gives its bearing from the camera's
optical axis, positive to the left: ``atan((cx - u) / fx)`` with ``cx`` the image's centre
column and ``fx`` the focal length in pixels, from the horizontal field of view
(:class:`CameraModel`). The detection's ``distance`` is the depth along the optical axis (what
a depth image holds: the ZED's ``depth_registered`` is Z, not the range), so in the camera's
frame the object lies ``distance`` ahead and ``distance * (cx - u) / fx`` to the left. The
camera sits at :data:`CAMERA_MOUNT` on the robot (:class:`CameraMount`, relative to
``base_link``). The simulated camera draws its boxes with the same model, so the tracker cannot
tell it from the ZED: :data:`CAMERA` holds the ZED 2's values at the 672 x 376 frame the 2018
Cyborg used.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TypeVar

import numpy as np

from cyborg.bus.msgs.cyborg_msgs.msg import TrackedObjects
from cyborg.bus.msgs.std_msgs.msg import String
from cyborg.interfaces.contract import Topic

# ---------------------------------------------------------------------- topics
OBJECTS = Topic("objects", TrackedObjects, depth=2)
"""The tracked objects of the robot under whose namespace it is (see the module's table)."""
SAY = Topic("say", String, depth=10)
"""Sentences for the robot to speak, under its namespace (see the module's table)."""
TOPICS: tuple[Topic, ...] = (OBJECTS, SAY)

MAP_FRAME = "map"
"""The frame of every tracked object's position and velocity."""


# ---------------------------------------------------------------------- the camera
Depth = TypeVar("Depth", float, np.ndarray)
"""A depth in metres, or an array of them."""


@dataclass(frozen=True)
class CameraModel:
    """A pinhole camera as far as bearings go: image size and horizontal field of view."""

    width: int
    """Image width in pixels."""
    height: int
    """Image height in pixels."""
    horizontal_fov: float
    """Horizontal field of view in radians."""
    min_range: float
    """Nearest depth the camera measures, metres."""
    max_range: float
    """Farthest depth the camera measures, metres."""
    depth_noise: tuple[float, float] = (0.01, 0.002)
    """``(a, b)``: a measured depth ``d`` is off by ``a d + b d²`` (one standard deviation),
    as stereo depth error grows with the square of the range: 1 % at 1 m, 2 % at 5 m, 5 % at
    20 m (the ZED 2 in the 2018 Cyborg's lighting)."""

    def depth_sigma(self, depth: Depth) -> Depth:
        """One standard deviation (m) of a depth measured at ``depth`` metres (or of each)."""
        linear, square = self.depth_noise
        sigma: Depth = linear * depth + square * depth * depth
        return sigma

    @property
    def centre_column(self) -> float:
        """The optical axis' column, ``cx`` (the image's middle, in pixels)."""
        return self.width / 2.0

    @property
    def focal_length(self) -> float:
        """``fx`` in pixels: half the width over the tangent of half the field of view."""
        return (self.width / 2.0) / math.tan(self.horizontal_fov / 2.0)

    def bearing(self, column: float) -> float:
        """The bearing (radians, positive left) of a point seen at image column ``column``."""
        return math.atan((self.centre_column - column) / self.focal_length)

    def column(self, bearing: float) -> float:
        """The image column where a point at ``bearing`` (radians, positive left) is seen."""
        return self.centre_column - self.focal_length * math.tan(bearing)


@dataclass(frozen=True)
class CameraMount:
    """Where the camera sits on the robot, relative to ``base_link`` (metres, radians)."""

    x: float
    """Ahead of the robot's centre."""
    y: float
    """To the left of the robot's centre."""
    z: float
    """Above the floor."""
    yaw: float
    """The optical axis' heading from the robot's, positive left."""


CAMERA = CameraModel(width=672, height=376, horizontal_fov=math.radians(110.0),
                     min_range=0.3, max_range=20.0)
"""The ZED 2 at 672 x 376 (the 2018 Cyborg's frame size): 110° horizontal field of view, depth
from 0.3 to 20 m (the ZED 2's data sheet)."""
CAMERA_MOUNT = CameraMount(x=0.2, y=0.0, z=1.1, yaw=0.0)
"""The ZED on the Cyborg: on the mast above the Pioneer LX's front, looking straight ahead."""

# ---------------------------------------------------------------------- the tracker's defaults
ASSOCIATION_GATE = 1.0
"""Metres: a detection further than this from every tracked object of its label starts a new
object."""
FORGET_AFTER = 5.0
"""Seconds unseen after which an object is forgotten (on the bus clock: simulated time too)."""
TRACKED_LABELS: tuple[str, ...] = ()
"""Labels tracked by default: empty means every label the detector gives."""
