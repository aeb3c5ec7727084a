"""An ARNL map as displays draw it: the ``map_geometry`` message and its publisher.

:func:`map_geometry` turns an :class:`~cyborg.nav.arnl_map.ArnlMap` into a
``cyborg_msgs/msg/MapGeometry``, all in metres and radians:

* ``lines`` holds ``x1 y1 x2 y2`` per wall and ``points`` ``x y`` per scanned point, as float32;
* each cairn becomes a ``cyborg_msgs/msg/MapObject`` with its kind as written, its category
  (the message's constants: ``GOAL``, ``DOCK``, ``FORBIDDEN_AREA`` ...), name, description and
  pose, and its outline where it has a region: the corners of
  :meth:`~cyborg.nav.map_objects.MapObject.corners`, so a ``ForbiddenArea`` comes already
  rotated about the map origin, a ``ForbiddenLine`` as its two endpoints, a ``RobotHome`` area
  as its four corners; a boundary declared by ``MapInfo: BoundaryType`` (a reflector, a
  measuring stick) is two endpoints as well (in ARIA boundaries are lines, sectors areas);
* ``source`` is the file's name without its folder, ``resolution`` the header's
  ``Resolution`` in metres (0 without one);
* ``hash`` is ``"sha256:<hex>"`` over the geometry as published (resolution, lines, points and
  objects, not the header or the file's name): the same map gives the same hash in every run and
  on every machine, and moving any point changes it. It is a hint for displays that drew the map
  before, not a proof: a display that caches by it should compute its own.

:class:`MapPublisher` publishes the message latched on a node
(:data:`~cyborg.interfaces.robot.MAP_GEOMETRY`, under the node's namespace), once at the start
and again each time the :class:`~cyborg.nav.services.NavigationMap` switches maps, so any
program that serves the navigation services (the simulator, a bridge to the real robot) shows
its map.
"""

from __future__ import annotations

import hashlib
import logging
import math
import struct
import time
from collections.abc import Callable
from pathlib import PureWindowsPath

import numpy as np

from cyborg.bus import Node
from cyborg.bus.msgs.builtin_interfaces.msg import Time
from cyborg.bus.msgs.cyborg_msgs.msg import MapGeometry
from cyborg.bus.msgs.cyborg_msgs.msg import MapObject as ObjectMessage
from cyborg.bus.msgs.geometry_msgs.msg import Pose2D as Pose2DMessage
from cyborg.bus.msgs.std_msgs.msg import Header
from cyborg.interfaces.robot import MAP_FRAME, MAP_GEOMETRY
from cyborg.nav import map_objects
from cyborg.nav.arnl_map import ArnlMap
from cyborg.nav.map_objects import MapObject, declared_categories
from cyborg.nav.services import NavigationMap

__all__ = ["CATEGORIES", "MapPublisher", "geometry_hash", "map_geometry"]

log = logging.getLogger("cyborg.nav")

CATEGORIES: dict[str, int] = {
    map_objects.OTHER: ObjectMessage.OTHER,
    map_objects.GOAL: ObjectMessage.GOAL,
    map_objects.GOAL_WITH_HEADING: ObjectMessage.GOAL_WITH_HEADING,
    map_objects.DOCK: ObjectMessage.DOCK,
    map_objects.HOME: ObjectMessage.HOME,
    map_objects.FORBIDDEN_LINE: ObjectMessage.FORBIDDEN_LINE,
    map_objects.FORBIDDEN_AREA: ObjectMessage.FORBIDDEN_AREA,
    map_objects.SIM_OBSTACLE: ObjectMessage.SIM_OBSTACLE,
}
"""A map object's category (:mod:`cyborg.nav.map_objects`) → MapObject.msg's constant."""

_HASH_VERSION = b"cyborg_msgs/MapGeometry 1\0"  # changes if what the hash covers changes
_NO_OUTLINE = np.zeros(0, np.float32)


def map_geometry(arnl_map: ArnlMap, stamp: Time | None = None) -> MapGeometry:
    """The map as a ``MapGeometry`` message, hash included (see the module's description).

    ``stamp`` goes into the header (zero when not given).
    """
    boundaries = {name for name, category in declared_categories(arnl_map.types).items()
                  if category == "BoundaryType"}
    objects = [_object(item, item.kind in boundaries) for item in arnl_map.objects]
    lines = _floats(arnl_map.lines)
    points = _floats(arnl_map.points)
    resolution = _resolution(arnl_map)
    return MapGeometry(
        header=Header(stamp=stamp or Time(sec=0, nanosec=0), frame_id=MAP_FRAME),
        source=PureWindowsPath(arnl_map.source).name,  # either separator
        hash=geometry_hash(resolution, lines, points, objects),
        resolution=resolution, lines=lines, points=points, objects=objects)


def geometry_hash(resolution: float, lines: np.ndarray, points: np.ndarray,
                  objects: list[ObjectMessage]) -> str:
    """``"sha256:<hex>"`` over the geometry as a MapGeometry carries it.

    Numbers are hashed as the message holds them (float32 arrays, float64 poses, little-endian),
    strings as UTF-8, each array and string after its length, so two different maps cannot
    run together into the same bytes.
    """
    digest = hashlib.sha256(_HASH_VERSION)
    digest.update(struct.pack("<fQQQ", resolution, len(lines), len(points), len(objects)))
    digest.update(np.asarray(lines, "<f4").tobytes())
    digest.update(np.asarray(points, "<f4").tobytes())
    for item in objects:
        for text in (item.kind, item.name, item.description):
            data = text.encode("utf-8", "surrogatepass")
            digest.update(struct.pack("<Q", len(data)))
            digest.update(data)
        pose = item.pose
        digest.update(struct.pack("<BdddQ", item.category, pose.x, pose.y, pose.theta,
                                  len(item.outline)))
        digest.update(np.asarray(item.outline, "<f4").tobytes())
    return "sha256:" + digest.hexdigest()


def _floats(array: np.ndarray) -> np.ndarray:
    """Rows of metres as one flat float32 array, row after row."""
    flat: np.ndarray = np.ascontiguousarray(array, np.float32).reshape(-1)
    return flat


def _resolution(arnl_map: ArnlMap) -> float:
    """The header's ``Resolution`` (mm) in metres; 0 when absent (the reader checked it)."""
    values = arnl_map.header.get("Resolution") or ["0"]
    try:
        millimetres = float(values[0])
    except ValueError:
        return 0.0
    return millimetres / 1000.0 if math.isfinite(millimetres) and millimetres > 0 else 0.0


def _object(item: MapObject, boundary: bool) -> ObjectMessage:
    """One cairn; ``boundary``: its region is a line (a declared ``BoundaryType``)."""
    if boundary and item.region is not None:
        outline = np.array(item.region, np.float32)
    else:
        corners = item.corners()
        outline = _NO_OUTLINE if corners is None else _floats(corners)
    return ObjectMessage(
        kind=item.kind, category=CATEGORIES.get(item.category, ObjectMessage.OTHER),
        name=item.name, description=item.description,
        pose=Pose2DMessage(x=float(item.x), y=float(item.y), theta=float(item.theta)),
        outline=outline)


def _wall_clock() -> Time:
    sec, nanosec = divmod(time.time_ns(), 1_000_000_000)
    return Time(sec=sec, nanosec=nanosec)


class MapPublisher:
    """Publishes the map in use on ``node``, latched, at once and after every switch.

    ``maps`` is the navigation map holder (its ``switched`` listeners call :meth:`publish`);
    ``stamp`` gives the header's time (the wall clock unless told otherwise; the simulator
    gives its simulated time). Publishing runs on the thread that switched maps.
    """

    def __init__(self, node: Node, maps: NavigationMap,
                 stamp: Callable[[], Time] | None = None) -> None:
        self.maps = maps
        self._stamp = stamp or _wall_clock
        self.publisher = MAP_GEOMETRY.publisher(node)
        self.last: MapGeometry | None = None
        """The message published last."""
        self.publish(maps.map)
        maps.switched.append(self.publish)

    def publish(self, arnl_map: ArnlMap) -> None:
        """Build the message for ``arnl_map`` and publish it."""
        started = time.perf_counter()
        message = map_geometry(arnl_map, self._stamp())
        self.publisher.publish(message)
        self.last = message
        log.debug("map_geometry %s: %d lines, %d points, %d objects, %s (%.0f ms)",
                  message.source, len(message.lines) // 4, len(message.points) // 2,
                  len(message.objects), message.hash[:19], (time.perf_counter() - started) * 1e3)
