"""A simulated 2D laser scanner (SICK S300-like), raycast on an occupancy grid.

Other robots' bodies, given as outlines (:mod:`cyborg.sim.bodies`), and people, given as
circles, are seen as well. Each beam
walks the grid cell by cell (the exact cell traversal of Amanatides and Woo), leaping through
open space by the distance to the nearest wall (:func:`cast_rays_far`), so a scan costs about
0.1 ms even on a large campus map; a scanner that has not moved since its last scan sees the
same walls without casting again. Ranges beyond the scanner's
reach read as ``range_max + 1`` ("nothing seen"), as ``sensor_msgs/LaserScan`` users expect
values outside ``[range_min, range_max]`` to be ignored.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numba import njit
from scipy import ndimage

from cyborg.sim.bodies import cast_onto_circles, cast_onto_fan

SQRT2 = math.sqrt(2.0)
LEAP = 2.0
"""Cells of room in which :func:`cast_rays_far` leaps on rather than walking cell by cell."""


@dataclass(frozen=True)
class LaserSpec:
    """Where the scanner sits on the robot and what it sees (the Pioneer LX's S300 by default).

    The field of view is in radians, centred on the robot's heading; ranges are in metres.
    """

    beams: int = 541
    field_of_view: float = math.radians(270.0)
    range_min: float = 0.05
    range_max: float = 30.0
    mount_x: float = 0.267  # metres ahead of the robot's centre
    noise: float = 0.006  # standard deviation of the range noise, metres

    @property
    def angle_min(self) -> float:
        """The first beam's angle (rad) relative to the robot's heading; the scan is symmetric."""
        return -self.field_of_view / 2

    @property
    def angle_increment(self) -> float:
        """Radians between neighbouring beams."""
        return self.field_of_view / (self.beams - 1)

    def angles(self) -> np.ndarray:
        """Beam angles relative to the robot's heading."""
        return self.angle_min + np.arange(self.beams) * self.angle_increment


@njit(cache=True)
def cast_rays(occupied: np.ndarray, origin_x: float, origin_y: float, resolution: float,
              x: float, y: float, angles: np.ndarray, range_max: float,
              out: np.ndarray) -> None:  # pragma: no cover - jit
    """Distance from ``(x, y)`` to the first occupied cell along each absolute angle."""
    rows, columns = occupied.shape
    gx = (x - origin_x) / resolution
    gy = (y - origin_y) / resolution
    limit = range_max / resolution
    for beam in range(angles.shape[0]):
        dx, dy = math.cos(angles[beam]), math.sin(angles[beam])
        c, r = math.floor(gx), math.floor(gy)
        step_c = 1 if dx > 0 else -1
        step_r = 1 if dy > 0 else -1
        delta_c = abs(1.0 / dx) if dx != 0 else np.inf
        delta_r = abs(1.0 / dy) if dy != 0 else np.inf
        next_c = ((c + 1 - gx) if dx > 0 else (gx - c)) * delta_c if dx != 0 else np.inf
        next_r = ((r + 1 - gy) if dy > 0 else (gy - r)) * delta_r if dy != 0 else np.inf
        travelled = 0.0
        hit = np.inf
        while travelled <= limit:
            if r < 0 or r >= rows or c < 0 or c >= columns:
                break
            if occupied[r, c]:
                hit = travelled
                break
            if next_c < next_r:
                travelled = next_c
                next_c += delta_c
                c += step_c
            else:
                travelled = next_r
                next_r += delta_r
                r += step_r
        out[beam] = hit * resolution if hit <= limit else np.inf


def room_grid(occupied: np.ndarray, clearance: np.ndarray, resolution: float) -> np.ndarray:
    """The grid :func:`cast_rays_far` walks: 0 where occupied, else 1 + the cells clear.

    ``clearance`` holds, per cell, the metres from its centre to the nearest occupied cell's
    centre (as :meth:`~cyborg.nav.grid.MapGrid.clearance` gives them). No point of a cell lies
    closer than that less ``sqrt(2)`` cells to any point of an occupied cell: the whole cells
    of that (less a hair, at most 254) are clear from anywhere in it. One byte a cell.
    """
    clear = np.floor(np.maximum(np.asarray(clearance, np.float64) / resolution - SQRT2 - 0.01,
                                0.0))
    room = (1 + np.minimum(clear, 254)).astype(np.uint8)
    room[np.asarray(occupied, bool)] = 0
    return room


@njit(cache=True)
def cast_rays_far(room: np.ndarray, origin_x: float, origin_y: float, resolution: float,
                  x: float, y: float, angles: np.ndarray, range_max: float,
                  out: np.ndarray) -> None:  # pragma: no cover - jit
    """:func:`cast_rays`, leaping through open space: the same ranges, fewer cells visited.

    ``room`` is :func:`room_grid`'s: a beam in a cell with more than :data:`LEAP` cells clear
    goes on that far from where it leaves the cell at once, and walks the grid cell by cell
    again from there; where it enters its first occupied cell (0) is the same (to rounding).
    One byte a cell is all it reads.
    """
    rows, columns = room.shape
    gx = (x - origin_x) / resolution
    gy = (y - origin_y) / resolution
    limit = range_max / resolution
    for beam in range(angles.shape[0]):
        dx, dy = math.cos(angles[beam]), math.sin(angles[beam])
        step_c = 1 if dx > 0 else -1
        step_r = 1 if dy > 0 else -1
        delta_c = abs(1.0 / dx) if dx != 0 else np.inf
        delta_r = abs(1.0 / dy) if dy != 0 else np.inf
        travelled = 0.0
        hit = np.inf
        restart = True
        c = r = 0
        next_c = next_r = 0.0
        while travelled <= limit:
            if restart:  # walk the cells on from the point `travelled` along the beam
                px, py = gx + travelled * dx, gy + travelled * dy
                c, r = math.floor(px), math.floor(py)
                next_c = (travelled + ((c + 1 - px) if dx > 0 else (px - c)) * delta_c
                          if dx != 0 else np.inf)
                next_r = (travelled + ((r + 1 - py) if dy > 0 else (py - r)) * delta_r
                          if dy != 0 else np.inf)
                restart = False
            if r < 0 or r >= rows or c < 0 or c >= columns:
                break
            here = room[r, c]
            if here == 0:
                hit = travelled
                break
            if here - 1 > LEAP:  # on from where the beam leaves the cell
                travelled = min(next_c, next_r) + (here - 1)
                restart = True
            elif next_c < next_r:
                travelled = next_c
                next_c += delta_c
                c += step_c
            else:
                travelled = next_r
                next_r += delta_r
                r += step_r
        out[beam] = hit * resolution if hit <= limit else np.inf


@njit(cache=True)
def beam_points(ranges: np.ndarray, relative: np.ndarray, x: float, y: float, theta: float,
                range_max: float) -> np.ndarray:  # pragma: no cover - jit
    """The (N, 2) points where beams from ``(x, y)`` with a range of at most ``range_max`` end.

    Beam ``k`` leaves at ``theta + relative[k]``; the points keep the beams' order.
    """
    points = np.empty((ranges.shape[0], 2))
    count = 0
    for beam in range(ranges.shape[0]):
        if ranges[beam] <= range_max:
            angle = theta + relative[beam]
            points[count, 0] = x + ranges[beam] * math.cos(angle)
            points[count, 1] = y + ranges[beam] * math.sin(angle)
            count += 1
    return points[:count].copy()


_NO_CORNERS = np.zeros((0, 2))
_NO_STARTS = np.zeros(1, np.int64)
_NO_CIRCLES = np.zeros((0, 3))


@njit(cache=True)
def _seen(walls: np.ndarray, corners: np.ndarray, starts: np.ndarray, circles: np.ndarray,
          x: float, y: float, theta: float, angle_min: float,
          increment: float, noise: np.ndarray, range_min: float,
          range_max: float) -> np.ndarray:  # pragma: no cover - jit
    """The ranges a scan reads: the walls' ``walls``, shortened by bodies and circles, noisy.

    The bodies are outlines one after another in ``corners`` (body ``k`` from ``starts[k]``
    to ``starts[k + 1]``), the circles (N, 3) rows of x, y, radius; beam ``k`` leaves
    ``(x, y)`` at ``theta + angle_min + k increment``. What is beyond ``range_max`` reads
    ``range_max + 1``; the rest gets ``noise`` and is kept within ``range_min`` and
    ``range_max + 1``.
    """
    ranges = walls.copy()
    for body in range(starts.shape[0] - 1):
        cast_onto_fan(corners[starts[body]:starts[body + 1]], x, y, angle_min + theta,
                      increment, ranges)
    if circles.shape[0]:
        cast_onto_circles(circles, x, y, angle_min + theta, increment, ranges)
    for beam in range(ranges.shape[0]):
        if ranges[beam] <= range_max:
            ranges[beam] = min(max(ranges[beam] + noise[beam], range_min), range_max + 1.0)
        else:
            ranges[beam] = range_max + 1.0
    return ranges


class Laser:
    """Scans an occupancy grid from a robot pose.

    ``occupied`` is a boolean (rows, columns) grid whose cell (0, 0) has its lower-left corner at
    ``origin`` (m), with ``resolution`` metres per cell; ``seed`` seeds the range noise;
    ``clearance``, the grid's metres to the nearest occupied cell (computed when not given).
    """

    def __init__(self, occupied: np.ndarray, origin: tuple[float, float], resolution: float,
                 spec: LaserSpec | None = None, seed: int = 0,
                 clearance: np.ndarray | None = None) -> None:
        self.occupied = np.ascontiguousarray(occupied, dtype=np.bool_)
        self.origin, self.resolution = origin, resolution
        self.spec = spec or LaserSpec()
        self._relative = self.spec.angles()
        self._ranges = np.empty(self.spec.beams)
        if clearance is None:
            clearance = (ndimage.distance_transform_edt(~self.occupied) * resolution
                         if self.occupied.any() else np.full(self.occupied.shape, 1e6))
        self._room = room_grid(self.occupied, clearance, resolution)
        self._walls = np.empty(self.spec.beams)  # the walls' ranges from `_walls_from`
        self._walls_from: tuple[float, float, float] | None = None
        self._random = np.random.default_rng(seed)

    def scan(self, x: float, y: float, theta: float, bodies: Sequence[np.ndarray] = (),
             circles: np.ndarray | None = None) -> np.ndarray:
        """Ranges in metres for each beam, from the scanner's mount on the robot at the pose.

        A beam reads ``range_max + 1`` where nothing is within reach. The pose is in metres and
        radians; ``bodies`` are other robots' outlines (K x 2 map coordinates each), seen
        like walls, and ``circles`` round bodies ((N, 3): x, y, radius; people).
        """
        spec = self.spec
        sx = x + spec.mount_x * math.cos(theta)
        sy = y + spec.mount_x * math.sin(theta)
        if self._walls_from != (sx, sy, theta):  # a scanner that stands sees the same walls
            cast_rays_far(self._room, self.origin[0], self.origin[1], self.resolution, sx, sy,
                          self._relative + theta, spec.range_max, self._walls)
            self._walls_from = (sx, sy, theta)
        corners, starts = _NO_CORNERS, _NO_STARTS
        if bodies:
            corners = np.ascontiguousarray(np.concatenate(bodies), dtype=np.float64)
            starts = np.cumsum([0, *(len(outline) for outline in bodies)])
        if circles is None or not len(circles):
            circles = _NO_CIRCLES
        noise = (self._random.normal(0.0, spec.noise, spec.beams) if spec.noise > 0
                 else np.zeros(spec.beams))
        return _seen(self._walls, corners, starts, np.ascontiguousarray(circles, np.float64),
                     sx, sy, theta, spec.angle_min, spec.angle_increment, noise,
                     spec.range_min, spec.range_max)

    def points(self, x: float, y: float, theta: float, ranges: np.ndarray) -> np.ndarray:
        """The (N, 2) map points where beams with a valid range hit."""
        spec = self.spec
        return beam_points(ranges, self._relative, x + spec.mount_x * math.cos(theta),
                           y + spec.mount_x * math.sin(theta), theta, spec.range_max)
