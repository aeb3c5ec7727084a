"""Rasterising a map: walls, forbidden zones and clearance on a regular grid.

A :class:`MapGrid` covers the map's extent (plus a margin) with square cells; row ``r`` and
column ``c`` hold the cell whose lower-left corner is ``origin + (c, r) * resolution``. Layers:

* ``walls``: cells holding a scanned point or crossed by a wall line (and the simulator's boxes
  when asked for);
* ``forbidden``: cells crossed by a forbidden line or inside a forbidden area;
* :meth:`clearance`: metres from each cell's centre to the nearest blocked cell — what the
  planner inflates by and the simulator checks collisions with.

:meth:`MapGrid.nearest_clear` answers "where near here can the robot stand?" on a clearance
layer, e.g. a start for a map that does not name one.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from scipy import ndimage

from cyborg.nav.arnl_map import ArnlMap
from cyborg.nav.map_limits import CHUNK, check_grid, grid_shape, segment_samples
from cyborg.nav.map_objects import MapObject


class ClearPoint(NamedTuple):
    """A point with room for the robot; ``enclosed``: inside the map's walls, not around them."""

    x: float
    y: float
    enclosed: bool


@dataclass
class MapGrid:
    """Walls and forbidden cells of a map at one resolution (metres per cell).

    ``origin_x`` and ``origin_y`` are the lower-left corner of cell (0, 0) in metres; ``walls``
    and ``forbidden`` are boolean (rows, columns) layers. Usually made by :meth:`from_map`.
    """

    origin_x: float
    origin_y: float
    resolution: float
    walls: np.ndarray
    forbidden: np.ndarray

    @classmethod
    def from_map(cls, arnl_map: ArnlMap, resolution: float = 0.1, *,
                 sim_obstacles: bool = False, margin: float = 1.0) -> MapGrid:
        """Rasterise ``arnl_map``; ``sim_obstacles`` adds the simulator's boxes to the walls.

        MapError (a ValueError naming the map) before anything is allocated if the grid would
        exceed the cell cap or drawing it the drawing cap (:mod:`cyborg.nav.map_limits`).
        """
        if not resolution > 0 or not math.isfinite(resolution):
            raise ValueError(f"grid resolution must be positive, not {resolution}")
        check_grid(arnl_map, resolution, margin)
        bounds = arnl_map.bounds()
        origin_x, origin_y = bounds[0] - margin, bounds[1] - margin
        rows, columns = grid_shape(bounds, resolution, margin)
        grid = cls(origin_x, origin_y, resolution, np.zeros((rows, columns), bool),
                   np.zeros((rows, columns), bool))
        grid.mark_points(grid.walls, arnl_map.points)
        grid.mark_segments(grid.walls, arnl_map.lines)
        for item in arnl_map.forbidden_lines():
            corners = item.corners()
            assert corners is not None
            grid.mark_segments(grid.forbidden, corners.reshape(1, 4))
        for item in arnl_map.forbidden_areas():
            grid.fill_area(grid.forbidden, item)
        if sim_obstacles:
            for item in arnl_map.sim_obstacles():
                grid.fill_area(grid.walls, item)
        return grid

    # ------------------------------------------------------------------ coordinates
    @property
    def shape(self) -> tuple[int, int]:
        """``(rows, columns)`` of the grid."""
        rows, columns = self.walls.shape
        return rows, columns

    def cell(self, x: float, y: float) -> tuple[int, int]:
        """``(row, column)`` of the cell holding ``(x, y)`` (may lie outside the grid)."""
        return (math.floor((y - self.origin_y) / self.resolution),
                math.floor((x - self.origin_x) / self.resolution))

    def inside(self, row: int, column: int) -> bool:
        """Whether the cell ``(row, column)`` lies on the grid."""
        rows, columns = self.shape
        return 0 <= row < rows and 0 <= column < columns

    def center(self, row: int, column: int) -> tuple[float, float]:
        """``(x, y)`` in metres of the centre of cell ``(row, column)``."""
        return (self.origin_x + (column + 0.5) * self.resolution,
                self.origin_y + (row + 0.5) * self.resolution)

    def cells_of(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Rows and columns of an (N, 2) array of points, clipped to the grid."""
        rows, columns = self.shape
        r = np.floor((points[:, 1] - self.origin_y) / self.resolution).astype(np.int64)
        c = np.floor((points[:, 0] - self.origin_x) / self.resolution).astype(np.int64)
        return np.clip(r, 0, rows - 1), np.clip(c, 0, columns - 1)

    # ------------------------------------------------------------------ drawing
    def mark_points(self, layer: np.ndarray, points: np.ndarray) -> None:
        """Mark the cells of ``layer`` holding an (N, 2) array of points (off-grid: the edge)."""
        if len(points):
            rows, columns = self.cells_of(points)
            layer[rows, columns] = True

    def mark_segments(self, layer: np.ndarray, segments: np.ndarray) -> None:
        """Mark the cells of ``layer`` that an (N, 4) array of segments passes through.

        Segments are sampled finely, a chunk of them at a time, so the samples never need more
        than a few MB.
        """
        if len(segments) == 0:
            return
        counts = segment_samples(segments, self.resolution)
        ends = np.cumsum(counts)
        begin = 0
        while begin < len(segments):
            done = int(ends[begin - 1]) if begin else 0
            end = max(begin + 1, int(np.searchsorted(ends, done + CHUNK, side="right")))
            self._mark_samples(layer, segments[begin:end], counts[begin:end])
            begin = end

    def _mark_samples(self, layer: np.ndarray, segments: np.ndarray, counts: np.ndarray) -> None:
        starts, ends = segments[:, :2], segments[:, 2:]
        owner = np.repeat(np.arange(len(segments)), counts)
        first = np.concatenate([[0], np.cumsum(counts)[:-1]])
        t = (np.arange(counts.sum()) - np.repeat(first, counts)) / np.repeat(counts - 1, counts)
        samples = starts[owner] + (ends - starts)[owner] * t[:, None]
        self.mark_points(layer, samples)

    def fill_area(self, layer: np.ndarray, area: MapObject) -> None:
        """Mark the cells of ``layer`` whose centres lie inside an area object.

        The area's rotation is included; rows are filled a band at a time, and the outline is
        drawn too, so thin areas stay closed. An object without an area marks nothing.
        """
        corners = area.corners()
        if corners is None or len(corners) != 4:
            return
        low_r, low_c = self.cells_of(corners.min(axis=0, keepdims=True))
        high_r, high_c = self.cells_of(corners.max(axis=0, keepdims=True))
        assert area.region is not None
        fx, fy, tx, ty = area.region
        cos, sin = math.cos(-area.theta), math.sin(-area.theta)
        band = max(1, CHUNK // int(high_c[0] - low_c[0] + 1))
        for top in range(int(low_r[0]), int(high_r[0]) + 1, band):
            r, c = np.mgrid[top:min(top + band, int(high_r[0]) + 1), low_c[0]:high_c[0] + 1]
            x = self.origin_x + (c + 0.5) * self.resolution
            y = self.origin_y + (r + 0.5) * self.resolution
            ux, uy = x * cos - y * sin, x * sin + y * cos
            inside = ((ux >= min(fx, tx)) & (ux <= max(fx, tx))
                      & (uy >= min(fy, ty)) & (uy <= max(fy, ty)))
            layer[r[inside], c[inside]] = True
        self.mark_segments(layer, np.array([[*corners[i], *corners[(i + 1) % 4]]
                                            for i in range(4)]))  # thin areas stay closed

    # ------------------------------------------------------------------ clearance
    def blocked(self, forbidden: bool = True) -> np.ndarray:
        """Cells the robot's centre can never be in: walls, and forbidden cells if asked."""
        return self.walls | self.forbidden if forbidden else self.walls.copy()

    def clearance(self, blocked: np.ndarray | None = None) -> np.ndarray:
        """Metres from each cell centre to the nearest blocked cell (float32; 0 when blocked)."""
        if blocked is None:
            blocked = self.blocked()
        if not blocked.any():
            return np.full(self.shape, np.float32(1e6))
        distance: np.ndarray = ndimage.distance_transform_edt(~blocked)
        return (distance * self.resolution).astype(np.float32)

    def nearest_clear(self, clearance: np.ndarray, x: float, y: float, needed: float,
                      within: np.ndarray | None = None) -> ClearPoint | None:
        """The centre of the cell nearest ``(x, y)`` with at least ``needed`` m of clearance.

        ``clearance`` is what :meth:`clearance` returns; only cells in the ``within`` mask count,
        if given. Returns None if no cell qualifies.

        Cells *enclosed* by the map win over cells outside its walls: free space that reaches
        the grid's border runs around the outside of the building, so a building shaped like
        an L, whose extent's centre lies in the open, still gets a point indoors. Only when
        no enclosed cell qualifies (an open map, walls with gaps, a room too small for the
        clearance) do outside cells count, and the answer says so (``enclosed`` False).
        """
        free = clearance >= needed
        labels, _count = ndimage.label(free)
        border = np.concatenate([labels[0], labels[-1], labels[:, 0], labels[:, -1]])
        outside = np.isin(labels, border[border > 0])
        allowed = free if within is None else free & within
        candidates = allowed & ~outside
        enclosed = bool(candidates.any())
        rows, columns = np.nonzero(candidates if enclosed else allowed)
        if len(rows) == 0:
            return None
        centres_x = self.origin_x + (columns + 0.5) * self.resolution
        centres_y = self.origin_y + (rows + 0.5) * self.resolution
        best = int(np.argmin(np.hypot(centres_x - x, centres_y - y)))
        return ClearPoint(float(centres_x[best]), float(centres_y[best]), enclosed)

    def clearance_at(self, clearance: np.ndarray, x: float, y: float) -> float:
        """Clearance at a point, 0 outside the grid."""
        row, column = self.cell(x, y)
        if not self.inside(row, column):
            return 0.0
        return float(clearance[row, column])
