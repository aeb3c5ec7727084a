"""Where a detection lies on the map: robot pose + camera mount + bearing + distance.

A :class:`Detection` is what the detector says of one box: its label, confidence, the depth
along the optical axis (``distance``) and the box centre's image column. :func:`locate` puts a
batch of them on the map, as :mod:`cyborg.interfaces.perception` defines the camera:

1. in the camera's frame the object lies ``distance`` ahead and ``distance * (cx - u) / fx``
   to the left (the pinhole model: the same ray as the bearing ``atan((cx - u) / fx)``);
2. the camera's mount (:data:`~cyborg.interfaces.perception.CAMERA_MOUNT`: ahead, left, yaw)
   moves that into the robot's frame, ``base_link``;
3. the robot's pose (x, y, heading on the map) moves it onto the map.

Each result, a :class:`Sighting`, keeps the distance and bearing from the robot's centre too
(what ``FaceObject`` turns by). The work is done on numpy arrays, so a frame of many detections
costs little more than one.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from cyborg.interfaces.perception import CAMERA, CAMERA_MOUNT, CameraModel, CameraMount


@dataclass(frozen=True)
class Detection:
    """One box of the detector, reduced to what placing it takes."""

    label: str
    confidence: float
    """0..1, the detector's score."""
    distance: float
    """Metres along the optical axis (the depth image's Z)."""
    column: float
    """The box centre's image column, pixels."""


@dataclass(frozen=True)
class RobotPose:
    """The robot on the map when the detections were made: metres and radians."""

    x: float
    y: float
    theta: float


@dataclass(frozen=True)
class Sighting:
    """A detection placed on the map."""

    label: str
    confidence: float
    x: float
    """Metres on the map."""
    y: float
    """Metres on the map."""
    distance: float
    """Metres from the robot's centre."""
    bearing: float
    """Radians from the robot's heading, positive left."""


def locate(detections: list[Detection], pose: RobotPose, camera: CameraModel = CAMERA,
           mount: CameraMount = CAMERA_MOUNT) -> list[Sighting]:
    """The detections on the map, seen by ``camera`` at ``mount`` from a robot at ``pose``.

    The detections are taken as they are: screen them first
    (:func:`cyborg.perception.screening.screen`) so that no distance is NaN or negative.
    """
    if not detections:
        return []
    depth = np.fromiter((d.distance for d in detections), float, len(detections))
    column = np.fromiter((d.column for d in detections), float, len(detections))
    ahead = depth
    left = depth * (camera.centre_column - column) / camera.focal_length
    cos_m, sin_m = math.cos(mount.yaw), math.sin(mount.yaw)
    robot_x = mount.x + ahead * cos_m - left * sin_m
    robot_y = mount.y + ahead * sin_m + left * cos_m
    cos_r, sin_r = math.cos(pose.theta), math.sin(pose.theta)
    map_x = pose.x + robot_x * cos_r - robot_y * sin_r
    map_y = pose.y + robot_x * sin_r + robot_y * cos_r
    distance = np.hypot(robot_x, robot_y)
    bearing = np.arctan2(robot_y, robot_x)
    return [Sighting(d.label, d.confidence, float(x), float(y), float(r), float(b))
            for d, x, y, r, b in zip(detections, map_x, map_y, distance, bearing, strict=True)]
