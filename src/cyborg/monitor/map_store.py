r"""Robots' maps as the page fetches them: checked, laid out as one binary blob, kept gzipped.

A robot publishes its map once (``map_geometry``, latched: cyborg_msgs/MapGeometry). The
monitor checks it, lays it out as a *blob* and keeps the blob's gzip under a key it computes
itself, ``sha256(blob)[:32]`` in hex: the ``hash`` a publisher writes is never trusted, so a
forged one cannot put another map under a key that pages cache for good. Robots on the same
map share one blob; a page fetches it once (``GET /api/map/{key}``, cached as immutable).

The blob, little-endian throughout::

    8 bytes   b"CYMAP\0\1\0"  magic and format version 1
    u32       header length   bytes of the JSON header below, a multiple of 4
    JSON      header          UTF-8, padded with spaces to a multiple of 4 bytes
    f32[]     lines           x1 y1 x2 y2 per wall line, m (counts.lines x 4 numbers)
    f32[]     points          x y per scanned point, m (counts.points x 2 numbers)

The header: ``{"format": "cyborg.map/1", "source", "frame", "resolution", "bounds": [min x,
min y, max x, max y], "counts": {"lines", "points", "objects"}, "objects": [{"kind",
"category", "name", "description", "pose": [x, y, θ], "outline": [x, y, ...]}]}``; ``bounds``
(m, outward to 1 mm) cover lines, points, object poses and outlines, ``[0, 0, 0, 0]`` for an
empty map. A map the monitor will not draw (more than :data:`POINT_LIMIT` points,
:data:`LINE_LIMIT` lines or :data:`OBJECT_LIMIT` objects, a NaN, a coordinate more than
:data:`~cyborg.monitor.robot_wire.WORLD_LIMIT` m away, arrays of the wrong shape) is refused
whole, with a warning that says why.

:class:`MapStore` keeps at most :data:`MAPS_KEPT` maps and :data:`BYTES_KEPT` bytes of gzip,
least recently used first out, but never a map a robot uses now.
"""

from __future__ import annotations

import gzip
import hashlib
import json
import math
import struct
import threading
from collections import OrderedDict
from collections.abc import Collection
from dataclasses import dataclass
from typing import Any

import numpy as np

from cyborg.bus.msgs.cyborg_msgs.msg import MapGeometry, MapObject
from cyborg.monitor.robot_wire import WORLD_LIMIT, Warnings, clip_text

MAGIC = b"CYMAP\x00\x01\x00"
FORMAT = "cyborg.map/1"
POINT_LIMIT = 2_000_000
LINE_LIMIT = 200_000
OBJECT_LIMIT = 10_000
OUTLINE_SIZES = (0, 4, 8)
"""Numbers an object's outline may have: none, a line's two ends, a rectangle's corners."""
CATEGORIES = range(8)
"""MapObject's categories (OTHER … SIM_OBSTACLE); others are drawn as OTHER."""
NAME_LIMIT, KIND_LIMIT, DESCRIPTION_LIMIT = 200, 100, 1000
MAPS_KEPT = 8
BYTES_KEPT = 64 << 20
GZIP_LEVEL = 6


class MapRefusedError(ValueError):
    """A map the monitor will not draw; the message says why."""


@dataclass(frozen=True)
class StoredMap:
    """One map as the monitor serves it."""

    key: str
    """``sha256(blob)[:32]``, hex: the name in ``/api/map/{key}``."""
    gzipped: bytes
    size: int
    """The blob's length before gzip, in bytes."""
    source: str
    counts: dict[str, int]
    objects: tuple[dict[str, Any], ...] = ()
    """The map's goals, docks, homes and other objects, as the blob's header has them."""

    @property
    def url(self) -> str:
        """Where the page fetches the blob."""
        return f"/api/map/{self.key}"


def _check_coordinates(values: np.ndarray, what: str) -> None:
    if values.size == 0:
        return
    if not np.isfinite(values).all():
        raise MapRefusedError(f"map: {what} hold a value that is not finite "
                         f"({_first_bad(values)}); map not shown")
    largest = float(np.abs(values).max())
    if largest > WORLD_LIMIT:
        raise MapRefusedError(f"map: {what} reach {largest:.6g} m from the origin, more than the "
                         f"{WORLD_LIMIT / 1000:g} km the monitor draws; map not shown")


def _first_bad(values: np.ndarray) -> str:
    return f"{float(values[~np.isfinite(values)][0]):.6g}"


def _array(values: Any, group: int, what: str, limit: int, unit: str) -> np.ndarray:
    array = np.asarray(values, dtype=np.float32).reshape(-1)
    if array.size % group:
        raise MapRefusedError(f"map: {what} has {array.size:,} numbers, not a multiple of {group}; "
                         "map not shown")
    count = array.size // group
    if count > limit:
        raise MapRefusedError(f"map: {count:,} {unit}, more than the {limit:,} the monitor draws; "
                         "map not shown")
    _check_coordinates(array, what)
    return array


def _object(index: int, item: MapObject, warnings: Warnings) -> dict[str, Any]:
    pose = (float(item.pose.x), float(item.pose.y), float(item.pose.theta))
    name, clipped_name = clip_text(item.name, NAME_LIMIT)
    if not all(math.isfinite(value) for value in pose):
        raise MapRefusedError(f"map: object {index} ({name!r}) has a pose that is not finite; map "
                         "not shown")
    if abs(pose[0]) > WORLD_LIMIT or abs(pose[1]) > WORLD_LIMIT:
        raise MapRefusedError(f"map: object {index} ({name!r}) lies more than "
                         f"{WORLD_LIMIT / 1000:g} km away; map not shown")
    outline = np.asarray(item.outline, dtype=np.float32).reshape(-1)
    if outline.size not in OUTLINE_SIZES:
        raise MapRefusedError(f"map: object {index} ({name!r}) has an outline of {outline.size} "
                         "numbers; expected 0, 4 or 8; map not shown")
    _check_coordinates(outline, f"object {index}'s outline")
    kind, clipped_kind = clip_text(item.kind, KIND_LIMIT)
    description, clipped_description = clip_text(item.description, DESCRIPTION_LIMIT)
    if clipped_name or clipped_kind or clipped_description:
        warnings.append(f"map: object {index}'s texts clipped")
    category = int(item.category)
    if category not in CATEGORIES:
        warnings.append(f"map: object {index} ({name!r}) has category {category}; drawn as "
                        "OTHER")
        category = 0
    return {"kind": kind, "category": category, "name": name, "description": description,
            "pose": [round(pose[0], 4), round(pose[1], 4), round(math.remainder(pose[2],
                                                                                math.tau), 4)],
            "outline": [round(float(value), 4) for value in outline.tolist()]}


def _bounds(arrays: list[np.ndarray]) -> list[float]:
    xs = [array[0::2] for array in arrays if array.size]
    ys = [array[1::2] for array in arrays if array.size]
    if not xs:
        return [0.0, 0.0, 0.0, 0.0]
    low_x = min(float(x.min()) for x in xs)
    low_y = min(float(y.min()) for y in ys)
    high_x = max(float(x.max()) for x in xs)
    high_y = max(float(y.max()) for y in ys)
    return [math.floor(low_x * 1000) / 1000, math.floor(low_y * 1000) / 1000,
            math.ceil(high_x * 1000) / 1000, math.ceil(high_y * 1000) / 1000]


def map_blob(message: MapGeometry) -> tuple[bytes, dict[str, Any], Warnings]:
    """The blob of ``message`` (see the module docstring), its header and any warnings.

    Raises :class:`MapRefusedError` for a map the monitor will not draw.
    """
    warnings: Warnings = []
    objects = list(message.objects)
    if len(objects) > OBJECT_LIMIT:
        raise MapRefusedError(f"map: {len(objects):,} objects, more than the {OBJECT_LIMIT:,} the "
                         "monitor draws; map not shown")
    lines = _array(message.lines, 4, "lines", LINE_LIMIT, "lines")
    points = _array(message.points, 2, "points", POINT_LIMIT, "points")
    described = [_object(index, item, warnings) for index, item in enumerate(objects)]
    source, _clipped = clip_text(str(message.source).replace("\\", "/").rpartition("/")[2],
                                 NAME_LIMIT)
    resolution = float(message.resolution)
    if not (math.isfinite(resolution) and 0.0 <= resolution <= 1000.0):
        warnings.append(f"map: resolution {resolution:.6g} m ignored")
        resolution = 0.0
    poses = np.array([value for item in described for value in item["pose"][:2]], np.float64)
    outlines = np.array([value for item in described for value in item["outline"]], np.float64)
    frame, _clipped = clip_text(message.header.frame_id, NAME_LIMIT)
    header = {"format": FORMAT, "source": source, "frame": frame,
              "resolution": round(resolution, 6),
              "bounds": _bounds([lines.astype(np.float64), points.astype(np.float64), poses,
                                 outlines]),
              "counts": {"lines": lines.size // 4, "points": points.size // 2,
                         "objects": len(described)},
              "objects": described}
    text = json.dumps(header, separators=(",", ":"), allow_nan=False).encode()
    text += b" " * (-len(text) % 4)
    blob = b"".join((MAGIC, struct.pack("<I", len(text)), text,
                     lines.astype("<f4").tobytes(), points.astype("<f4").tobytes()))
    return blob, header, warnings


def map_key(blob: bytes) -> str:
    """The key a blob is kept and served under: the first 32 hex digits of its SHA-256."""
    return hashlib.sha256(blob).hexdigest()[:32]


class MapStore:
    """The maps the monitor serves, by key; safe to use from several threads."""

    def __init__(self, maps: int = MAPS_KEPT, size: int = BYTES_KEPT) -> None:
        self.maps_kept, self.bytes_kept = maps, size
        self._maps: OrderedDict[str, StoredMap] = OrderedDict()
        self._lock = threading.Lock()
        self.fetches = 0
        """Blobs served whole (not 304): how often pages actually fetched a map."""

    def put(self, message: MapGeometry, in_use: Collection[str] = ()
            ) -> tuple[StoredMap | None, Warnings]:
        """Checks and keeps the map of ``message``: the stored map (None if refused), warnings.

        Slow for big maps (gzip): call it from a worker thread. Maps under ``in_use`` keys are
        never dropped to make room.
        """
        try:
            blob, header, warnings = map_blob(message)
        except MapRefusedError as exc:
            return None, [str(exc)]
        key = map_key(blob)
        with self._lock:
            found = self._maps.get(key)
            if found is not None:
                self._maps.move_to_end(key)
                return found, warnings
        stored = StoredMap(key, gzip.compress(blob, GZIP_LEVEL, mtime=0), len(blob),
                           header["source"], header["counts"], tuple(header["objects"]))
        with self._lock:
            self._maps[key] = stored
            self._maps.move_to_end(key)
            self._evict({*in_use, key})
        return stored, warnings

    def _evict(self, keep: Collection[str]) -> None:
        for key in list(self._maps):
            if len(self._maps) <= self.maps_kept and self.stored_bytes() <= self.bytes_kept:
                return
            if key not in keep:
                del self._maps[key]

    def stored_bytes(self) -> int:
        """Bytes of gzip kept."""
        return sum(len(stored.gzipped) for stored in self._maps.values())

    def get(self, key: str) -> StoredMap | None:
        """The map under ``key``, or None; it becomes the most recently used."""
        with self._lock:
            found = self._maps.get(key)
            if found is not None:
                self._maps.move_to_end(key)
            return found

    def __contains__(self, key: object) -> bool:
        """Whether a map is kept under ``key``."""
        with self._lock:
            return key in self._maps

    def __len__(self) -> int:
        """How many maps are kept."""
        return len(self._maps)
