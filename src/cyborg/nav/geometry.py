"""Poses and paths in the map frame (metres, radians), convertible to and from ROS messages.

:class:`Point`, :class:`Quaternion` and :class:`Pose` mirror ``geometry_msgs``; :class:`Pose2D`
is what a ground robot mostly needs (x, y, heading). :class:`Path` is a polyline with a length,
the distance still to go from a position, and a point a given distance ahead ("carrot").

``from_message`` accepts any object with the ROS fields (a bus message or a plain namespace);
``to_message()`` builds the bus message, an instance of the class from :mod:`cyborg.bus.msgs`
(``geometry_msgs.msg.Pose2D`` for :class:`Pose2D`).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numba import njit

from cyborg.bus.msgs.builtin_interfaces import msg as builtin_interfaces
from cyborg.bus.msgs.geometry_msgs import msg as geometry_msgs
from cyborg.bus.msgs.nav_msgs import msg as nav_msgs
from cyborg.bus.msgs.std_msgs import msg as std_msgs


def normalize_angle(angle: float) -> float:
    """The same angle in [-pi, pi)."""
    return (angle + math.pi) % (2 * math.pi) - math.pi


@dataclass(frozen=True)
class Point:
    """A point in space, in metres."""

    x: float = 0.0
    y: float = 0.0
    z: float = 0.0

    def distance_to(self, other: Point) -> float:
        """The straight-line distance to ``other`` in metres, in three dimensions."""
        return math.dist((self.x, self.y, self.z), (other.x, other.y, other.z))

    @classmethod
    def from_message(cls, message: Any) -> Point:
        """From a ``geometry_msgs/Point`` or anything with ``x``, ``y`` and ``z``."""
        return cls(float(message.x), float(message.y), float(message.z))

    def to_message(self) -> geometry_msgs.Point:
        """As ``geometry_msgs/Point``."""
        return geometry_msgs.Point(x=self.x, y=self.y, z=self.z)


@dataclass(frozen=True)
class Quaternion:
    """An orientation as a unit quaternion; the default is no rotation."""

    x: float = 0.0
    y: float = 0.0
    z: float = 0.0
    w: float = 1.0

    @classmethod
    def from_yaw(cls, yaw: float) -> Quaternion:
        """A rotation about the vertical axis by ``yaw`` radians."""
        return cls(0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))

    @property
    def yaw(self) -> float:
        """The heading in radians (rotation about z), in [-pi, pi)."""
        siny = 2 * (self.w * self.z + self.x * self.y)
        cosy = 1 - 2 * (self.y * self.y + self.z * self.z)
        return normalize_angle(math.atan2(siny, cosy))

    @classmethod
    def from_message(cls, message: Any) -> Quaternion:
        """From a ``geometry_msgs/Quaternion`` or anything with ``x``, ``y``, ``z``, ``w``."""
        return cls(float(message.x), float(message.y), float(message.z), float(message.w))

    def to_message(self) -> geometry_msgs.Quaternion:
        """As ``geometry_msgs/Quaternion``."""
        return geometry_msgs.Quaternion(x=self.x, y=self.y, z=self.z, w=self.w)


@dataclass(frozen=True)
class Pose2D:
    """A ground robot's pose: position in metres, heading in radians."""

    x: float = 0.0
    y: float = 0.0
    theta: float = 0.0

    def distance_to(self, other: Pose2D | Point) -> float:
        """The distance in metres to ``other`` on the ground plane (heights are ignored)."""
        return math.hypot(self.x - other.x, self.y - other.y)

    def to_pose(self) -> Pose:
        """The same pose in three dimensions: on the ground, turned about the vertical axis."""
        return Pose(Point(self.x, self.y), Quaternion.from_yaw(self.theta))

    @classmethod
    def from_message(cls, message: Any) -> Pose2D:
        """From ``geometry_msgs/Pose2D`` or ``geometry_msgs/Pose``."""
        if hasattr(message, "position"):
            return Pose.from_message(message).to_pose2d()
        return cls(float(message.x), float(message.y), float(message.theta))

    def to_message(self) -> geometry_msgs.Pose2D:
        """As ``geometry_msgs/Pose2D``."""
        return geometry_msgs.Pose2D(x=self.x, y=self.y, theta=self.theta)


@dataclass(frozen=True)
class Pose:
    """A position (metres) and an orientation in three dimensions, as ``geometry_msgs/Pose``."""

    position: Point = Point()
    orientation: Quaternion = Quaternion()

    def to_pose2d(self) -> Pose2D:
        """The pose on the ground plane: x, y and the heading about the vertical axis."""
        return Pose2D(self.position.x, self.position.y, self.orientation.yaw)

    @classmethod
    def from_message(cls, message: Any) -> Pose:
        """From a ``geometry_msgs/Pose`` or anything with its fields."""
        return cls(Point.from_message(message.position),
                   Quaternion.from_message(message.orientation))

    def to_message(self) -> geometry_msgs.Pose:
        """As ``geometry_msgs/Pose``."""
        return geometry_msgs.Pose(position=self.position.to_message(),
                                  orientation=self.orientation.to_message())


class Path:
    """A polyline of waypoints (metres) from start to goal, with an optional final heading."""

    def __init__(self, points: Sequence[Sequence[float]] | np.ndarray,
                 final_heading: float | None = None) -> None:
        array = np.asarray(points, dtype=np.float64).reshape(-1, 2)
        if len(array) == 0:
            raise ValueError("a path needs at least one point")
        self.points = array
        self.final_heading = final_heading
        steps = np.hypot(*np.diff(array, axis=0).T) if len(array) > 1 else np.zeros(0)
        self._cumulative = np.concatenate([[0.0], np.cumsum(steps)])

    @property
    def length(self) -> float:
        """Length in metres along the polyline."""
        return float(self._cumulative[-1])

    @property
    def start(self) -> Pose2D:
        """The first waypoint, heading along the path (see :meth:`heading_at`)."""
        return Pose2D(float(self.points[0, 0]), float(self.points[0, 1]), self.heading_at(0.0))

    @property
    def goal(self) -> Pose2D:
        """The last waypoint, with the final heading if there is one, else the last segment's."""
        heading = self.final_heading if self.final_heading is not None else self.heading_at(
            self.length)
        return Pose2D(float(self.points[-1, 0]), float(self.points[-1, 1]), heading)

    def __len__(self) -> int:
        return len(self.points)

    def project(self, x: float, y: float) -> tuple[float, float]:
        """``(distance along the path, distance from it)`` of the nearest point of the path."""
        if len(self.points) == 1:
            return 0.0, math.hypot(x - self.points[0, 0], y - self.points[0, 1])
        along, gap = _nearest_on(self.points, self._cumulative, float(x), float(y))
        return float(along), float(gap)

    def remaining_from(self, x: float, y: float) -> float:
        """Metres left to the goal from the point of the path nearest to ``(x, y)``."""
        along, _gap = self.project(x, y)
        return self.length - along

    def point_at(self, distance: float) -> tuple[float, float]:
        """The point ``distance`` metres along the path (clamped to its ends)."""
        distance = min(max(distance, 0.0), self.length)
        index = int(np.searchsorted(self._cumulative, distance, side="right")) - 1
        index = min(index, len(self.points) - 2)
        if index < 0:
            return float(self.points[0, 0]), float(self.points[0, 1])
        span = self._cumulative[index + 1] - self._cumulative[index]
        t = 0.0 if span == 0 else (distance - self._cumulative[index]) / span
        point = self.points[index] + t * (self.points[index + 1] - self.points[index])
        return float(point[0]), float(point[1])

    def sample(self, start: float, stop: float, step: float) -> np.ndarray:
        """Points every ``step`` metres along the path from ``start`` up to ``stop``."""
        first, last = max(start, 0.0), min(stop, self.length)
        if not last > first or not step > 0:
            return np.zeros((0, 2))
        return _sample(self.points, self._cumulative, first, last, step)

    def heading_at(self, distance: float) -> float:
        """Direction of travel at ``distance`` along the path (0 for a single point)."""
        if len(self.points) < 2:
            return self.final_heading or 0.0
        index = int(np.searchsorted(self._cumulative, min(distance, self.length), side="right"))
        index = min(max(index - 1, 0), len(self.points) - 2)
        dx, dy = self.points[index + 1] - self.points[index]
        return math.atan2(dy, dx)

    def advance_to(self, x: float, y: float) -> Path:
        """The rest of the path from the point nearest to ``(x, y)`` onwards."""
        along, _gap = self.project(x, y)
        index = int(np.searchsorted(self._cumulative, along, side="right"))
        rest = np.vstack([self.point_at(along), self.points[index:]])
        return Path(rest, self.final_heading)

    def poses(self) -> list[Pose2D]:
        """Waypoints as poses heading along the path; the last one takes the final heading."""
        result = [Pose2D(float(x), float(y), self.heading_at(float(d)))
                  for (x, y), d in zip(self.points, self._cumulative, strict=True)]
        result[-1] = self.goal
        return result

    def to_message(self, frame_id: str = "map",
                   stamp: builtin_interfaces.Time | None = None) -> nav_msgs.Path:
        """As ``nav_msgs/Path`` in ``frame_id``, stamped ``stamp`` (None: time zero).

        The path and every pose in it share one header.
        """
        header = std_msgs.Header(
            stamp=stamp if stamp is not None else builtin_interfaces.Time(sec=0, nanosec=0),
            frame_id=frame_id)
        return nav_msgs.Path(header=header, poses=[
            geometry_msgs.PoseStamped(header=header, pose=pose.to_pose().to_message())
            for pose in self.poses()])

    @classmethod
    def from_message(cls, message: Any) -> Path:
        """From a ``nav_msgs/Path``: its positions, and its last orientation as the final heading.

        Raises ValueError for a path without poses.
        """
        poses = [Pose.from_message(stamped.pose) for stamped in message.poses]
        if not poses:
            raise ValueError("nav_msgs/Path without poses")
        return cls([(pose.position.x, pose.position.y) for pose in poses],
                   poses[-1].orientation.yaw)

    @classmethod
    def through(cls, poses: Iterable[Pose2D]) -> Path:
        """The path through the positions of ``poses``, ending with the last one's heading."""
        items = list(poses)
        return cls([(pose.x, pose.y) for pose in items], items[-1].theta if items else None)

    def __repr__(self) -> str:
        return f"Path({len(self.points)} points, {self.length:.2f} m)"


@njit(cache=True)
def _sample(points: np.ndarray, cumulative: np.ndarray, first: float, last: float,
            step: float) -> np.ndarray:  # pragma: no cover - jit
    """The points at ``first``, ``first + step``, ... short of ``last`` metres along the path.

    As ``np.interp`` at ``np.arange(first, last, step)``: between the points around each
    distance, the first point where a segment has no length.
    """
    count = math.ceil((last - first) / step)
    out = np.empty((count, 2))
    segment = 0
    for k in range(count):
        distance = first + k * step
        while segment < cumulative.shape[0] - 2 and cumulative[segment + 1] <= distance:
            segment += 1
        span = cumulative[segment + 1] - cumulative[segment] if cumulative.shape[0] > 1 else 0.0
        share = (distance - cumulative[segment]) / span if span > 0 else 0.0
        share = min(max(share, 0.0), 1.0)
        out[k, 0] = points[segment, 0] + share * (points[min(segment + 1, points.shape[0] - 1), 0]
                                                  - points[segment, 0])
        out[k, 1] = points[segment, 1] + share * (points[min(segment + 1, points.shape[0] - 1), 1]
                                                  - points[segment, 1])
    return out


@njit(cache=True)
def _nearest_on(points: np.ndarray, cumulative: np.ndarray, x: float,
                y: float) -> tuple[float, float]:  # pragma: no cover - jit
    """``(along, gap)`` of the point of the polyline ``points`` nearest to ``(x, y)``.

    ``cumulative`` holds the metres along the polyline at each point; the first of equally
    near segments wins. The robot's follower asks this ten times a second.
    """
    best_gap, best_along = np.inf, 0.0
    for k in range(points.shape[0] - 1):
        ax, ay = points[k, 0], points[k, 1]
        sx, sy = points[k + 1, 0] - ax, points[k + 1, 1] - ay
        squared = sx * sx + sy * sy
        t = ((x - ax) * sx + (y - ay) * sy) / (squared if squared > 0 else 1.0)
        t = min(max(t, 0.0), 1.0)
        gap = math.hypot(ax + sx * t - x, ay + sy * t - y)
        if gap < best_gap:
            best_gap, best_along = gap, cumulative[k] + t * math.sqrt(squared)
    return best_along, best_gap
