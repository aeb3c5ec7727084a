"""A simulated stereo camera with an object detector: what a ZED 2 and YOLO would report.

The camera sits on the robot as on the Cyborg (:class:`CameraSpec`: facing forward, ahead of
the axle and a metre up) and looks through a pinhole of the ZED 2's horizontal field of view
(110°) onto an image of 672 x 376 pixels (the ZED's WVGA mode, the 2018 detector's input).
Mount and optics default to the contract's (:data:`cyborg.interfaces.perception.CAMERA_MOUNT`
and :data:`~cyborg.interfaces.perception.CAMERA`), which the tracker places detections with:
a camera mounted elsewhere than the tracker believes puts every person off by the difference.
For each thing in view (:mod:`cyborg.sim.sights`) it decides what a detector on that frame
would report:

* **in view**: its centre within the field of view, between ``range_min`` and ``range_max``
  (0.3 to 20 m, the ZED 2's depth range);
* **occlusion**: three rays from the camera (at the centre and at 70 % of the radius to each
  side) against the walls of the occupancy grid and the other bodies (people, robots); the
  share of rays that reach it scales the chance of a detection;
* **misses**: detected with probability ``detect_near`` up to ``sure_range``, falling
  linearly to ``detect_far`` at ``range_max``, times the visible share;
* **noise**: the distance (along the optical axis, as the detector's depth median gives it)
  with a standard deviation of ``distance_noise[0] d + distance_noise[1] d²`` (1 % at 1 m,
  2 % at 5 m, 5 % at 20 m: stereo depth error grows with the square of the range), the
  bearing with ``bearing_noise``, the box's size with ``size_noise``; the confidence falls with
  range (0.95 near, 0.55 at ``range_max``, ± 0.05);
* **no false positives**: nothing is reported that is not there (a real detector's rare false
  boxes are not simulated);
* **boxes** from the pinhole model: the centre column from the bearing, the width from the
  body's diameter, the top from its height and the bottom from the floor, clipped to the
  image (a box with nothing left inside the image is dropped).

Everything random comes from one generator seeded by ``seed``: the same run sees the same.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from cyborg.interfaces.perception import CAMERA, CAMERA_MOUNT
from cyborg.sim.camera_view import frame_view
from cyborg.sim.sights import Sights


@dataclass(frozen=True)
class CameraSpec:
    """The camera's mount, optics, rate and detection model; lengths in m, angles in rad."""

    width: int = CAMERA.width  # pixels
    height: int = CAMERA.height
    field_of_view: float = CAMERA.horizontal_fov  # horizontal; square pixels
    mount_x: float = CAMERA_MOUNT.x  # ahead of the robot's centre
    mount_height: float = CAMERA_MOUNT.z  # above the floor, looking level
    range_min: float = CAMERA.min_range
    range_max: float = CAMERA.max_range
    rate: float = 10.0  # frames per simulated second (at most the simulator's sensor rate)
    detect_near: float = 0.97
    detect_far: float = 0.3
    sure_range: float = 5.0
    distance_noise: tuple[float, float] = CAMERA.depth_noise
    bearing_noise: float = math.radians(1.0)
    size_noise: float = 0.05  # relative

    @property
    def focal(self) -> float:
        """The focal length in pixels, from the width and the horizontal field of view."""
        return self.width / 2 / math.tan(self.field_of_view / 2)

    def distance_sigma(self, distance: np.ndarray) -> np.ndarray:
        """The standard deviation (m) of a measured distance at ``distance`` m."""
        linear, square = self.distance_noise
        result: np.ndarray = linear * distance + square * distance ** 2
        return result

    def detection_chance(self, distance: np.ndarray) -> np.ndarray:
        """The chance that a fully visible thing at ``distance`` m is detected."""
        share = np.clip((distance - self.sure_range) / (self.range_max - self.sure_range),
                        0.0, 1.0)
        result: np.ndarray = self.detect_near + (self.detect_far - self.detect_near) * share
        return result


@dataclass(frozen=True)
class SeenObject:
    """One detection, as the real detector reports it.

    A :class:`~cyborg.interfaces.detection_messages.BoxedObject`: label, confidence, box
    ``x1, y1, x2, y2`` in pixels, distance along the optical axis (m).
    """

    label: str
    confidence: float
    box: tuple[float, float, float, float]
    distance: float


RAY_SPREAD = 0.7
"""Where the side rays of the occlusion test aim: this share of the radius off the centre."""
NO_OUTLINES, NO_STARTS, NO_CIRCLES = np.zeros((0, 2)), np.zeros(1, np.int64), np.zeros((0, 3))
"""No other bodies: no outlines' corners, the start of none, no round bodies."""


class SimCamera:
    """Detects :class:`~cyborg.sim.sights.Sights` from a robot pose; see the module doc.

    ``occupied`` is the world's wall grid (rows, columns; cell (0, 0)'s corner at ``origin``,
    ``resolution`` m per cell), as the laser scans it.
    """

    def __init__(self, occupied: np.ndarray, origin: tuple[float, float], resolution: float,
                 spec: CameraSpec | None = None, seed: int = 0) -> None:
        self.look_at(occupied, origin, resolution)
        self.spec = spec or CameraSpec()
        self._random = np.random.default_rng(seed)

    def look_at(self, occupied: np.ndarray, origin: tuple[float, float],
                resolution: float) -> None:
        """See the walls of another grid from now on (the robot switched maps)."""
        self.occupied = np.ascontiguousarray(occupied, dtype=np.bool_)
        self.origin, self.resolution = origin, resolution

    def where(self, x: float, y: float, theta: float) -> tuple[float, float]:
        """The camera's position in the map for the robot at ``(x, y, theta)``."""
        return (x + self.spec.mount_x * math.cos(theta),
                y + self.spec.mount_x * math.sin(theta))

    def observe(self, x: float, y: float, theta: float, sights: Sights,
                bodies: Sequence[np.ndarray] = (),
                circles: np.ndarray | None = None) -> list[SeenObject]:
        """What the detector reports on a frame taken with the robot at ``(x, y, theta)``.

        ``sights`` are the things that may be detected, and they hide each other; ``bodies``
        (outlines, K x 2) and ``circles`` ((M, 3): x, y, radius) what else may hide them
        besides the walls (the things themselves may be among them: a thing does not hide
        itself).
        """
        spec = self.spec
        if not sights.labels:
            return []
        cx, cy = self.where(x, y, theta)
        outlines, starts = NO_OUTLINES, NO_STARTS
        if bodies:
            corners = [np.asarray(outline, dtype=np.float64).reshape(-1, 2) for outline in bodies]
            outlines = np.concatenate(corners)
            starts = np.cumsum([0] + [len(outline) for outline in corners])
        chosen, distance, bearing, visible = frame_view(
            np.ascontiguousarray(sights.positions, dtype=np.float64),
            np.ascontiguousarray(sights.radii, dtype=np.float64), cx, cy, theta,
            spec.field_of_view / 2, spec.range_min, spec.range_max, RAY_SPREAD,
            self.occupied, self.origin[0], self.origin[1], self.resolution, outlines, starts,
            NO_CIRCLES if circles is None else np.ascontiguousarray(circles, dtype=np.float64))
        if len(chosen) == 0:
            return []
        chance = spec.detection_chance(distance) * visible
        detected = self._random.random(len(chosen)) < chance
        found = np.flatnonzero(detected)
        noise = self._random.standard_normal((len(found), 4))  # distance, bearing, size, score
        seen = []
        for row, index in enumerate(found):
            thing = chosen[index]
            seen.append(self._report(sights.labels[thing], float(distance[index]),
                                     float(bearing[index]), float(sights.radii[thing]),
                                     float(sights.heights[thing]), noise[row]))
        return [item for item in seen if item is not None]

    def _report(self, label: str, distance: float, bearing: float, radius: float,
                height: float, noise: np.ndarray) -> SeenObject | None:
        """The detection of a thing at ``distance`` and ``bearing``; None off the image.

        ``noise`` holds four standard normal draws: distance, bearing, size and confidence.
        """
        spec = self.spec
        depth = distance * math.cos(bearing)  # along the optical axis
        linear, square = spec.distance_noise
        measured = min(max(spec.range_min,  # the depth a ZED reports stays within its range
                           depth + float(noise[0]) * (linear * depth + square * depth * depth)),
                       spec.range_max)
        seen_bearing = bearing + float(noise[1]) * spec.bearing_noise
        scale = 1.0 + float(noise[2]) * spec.size_noise
        focal, middle_x, middle_y = spec.focal, spec.width / 2, spec.height / 2
        column = middle_x - focal * math.tan(seen_bearing)
        half_width = focal * radius * scale / depth
        top = middle_y - focal * (height - spec.mount_height) * scale / depth
        bottom = middle_y + focal * spec.mount_height * scale / depth
        x1, x2 = max(0.0, column - half_width), min(float(spec.width), column + half_width)
        y1, y2 = max(0.0, top), min(float(spec.height), bottom)
        if x2 - x1 < 1.0 or y2 - y1 < 1.0:
            return None
        closeness = 1.0 - min(distance / spec.range_max, 1.0)
        confidence = min(max(0.55 + 0.4 * closeness + 0.05 * float(noise[3]), 0.5), 0.99)
        return SeenObject(label, confidence, (x1, y1, x2, y2), measured)
