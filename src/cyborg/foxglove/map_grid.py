"""A robot's map as an occupancy grid (``nav_msgs/msg/OccupancyGrid``) for Foxglove's 3D panel.

:func:`occupancy_grid` rasterises a ``cyborg_msgs/msg/MapGeometry`` with navigation's grid
(:class:`~cyborg.nav.grid.MapGrid`): walls and scanned points are :data:`OCCUPIED`, forbidden
lines and areas :data:`FORBIDDEN`, everything else :data:`FREE` (an ARNL map knows no unknown
space). Cells are the map's own resolution held between :data:`FINEST` and :data:`COARSEST`
(5 and 10 cm), coarser still by doubling when the grid would pass :data:`MAX_CELLS`, so any map
from the bus costs a bounded grid. The grid covers the map's extent plus :data:`MARGIN`; its
origin is the lower-left corner of cell (0, 0), rows running along y, in the ``map`` frame.
Coordinates that are not finite are left out.
"""

from __future__ import annotations

import math

import numpy as np

from cyborg.bus.msgs.cyborg_msgs.msg import MapGeometry, MapObject
from cyborg.bus.msgs.geometry_msgs.msg import Point, Pose, Quaternion
from cyborg.bus.msgs.nav_msgs.msg import MapMetaData, OccupancyGrid
from cyborg.bus.msgs.std_msgs.msg import Header
from cyborg.nav.grid import MapGrid

FREE = 0
"""A cell the robot may drive through."""
OCCUPIED = 100
"""A cell holding a wall or a scanned point."""
FORBIDDEN = 60
"""A cell on a forbidden line or in a forbidden area (drawn grey, walls black)."""
FINEST = 0.05
"""The finest cell, m: a map of finer resolution is drawn at this."""
COARSEST = 0.1
"""The coarsest cell, m, for a map whose grid stays under :data:`MAX_CELLS`."""
MAX_CELLS = 4_000_000
"""The most cells a grid may have (4 MB of message); coarser cells keep it under."""
MARGIN = 1.0
"""Metres of free space around the map's extent."""


def grid_resolution(map_resolution: float, width: float, height: float) -> float:
    """Metres per cell for a map of ``map_resolution`` spanning ``width`` by ``height`` m.

    ValueError when the span is not finite (coordinates far beyond any building).
    """
    if not (math.isfinite(width) and math.isfinite(height)):
        raise ValueError(f"map_geometry: the map spans {width} x {height} m, too far to draw")
    resolution = min(max(map_resolution, FINEST), COARSEST) \
        if math.isfinite(map_resolution) else COARSEST
    while (width / resolution + 2) * (height / resolution + 2) > MAX_CELLS:
        resolution *= 2
    return float(np.float32(resolution))  # as the message carries it, so readers' cells agree


def occupancy_grid(message: MapGeometry) -> OccupancyGrid:
    """The map of ``message`` as an occupancy grid (see the module's description)."""
    lines = _finite(np.asarray(message.lines, np.float64), 4)
    points = _finite(np.asarray(message.points, np.float64), 2)
    outlines = [(item, _finite(np.asarray(item.outline, np.float64), 2))
                for item in message.objects]
    corners = [lines[:, :2], lines[:, 2:], points, *(outline for _, outline in outlines)]
    everything = np.concatenate([block for block in corners if len(block)] or
                                [np.zeros((1, 2))])
    low, high = everything.min(axis=0) - MARGIN, everything.max(axis=0) + MARGIN
    resolution = grid_resolution(float(message.resolution), *(high - low))
    columns, rows = (np.ceil((high - low) / resolution).astype(int) + 1).tolist()
    grid = MapGrid(float(low[0]), float(low[1]), resolution, np.zeros((rows, columns), bool),
                   np.zeros((rows, columns), bool))
    grid.mark_points(grid.walls, points)
    grid.mark_segments(grid.walls, lines)
    for item, outline in outlines:
        if item.category == MapObject.FORBIDDEN_LINE and len(outline) == 2:
            grid.mark_segments(grid.forbidden, outline.reshape(1, 4))
        elif item.category == MapObject.FORBIDDEN_AREA and len(outline) >= 3:
            _fill(grid, outline)
    cells = np.full((rows, columns), FREE, np.int8)
    cells[grid.forbidden] = FORBIDDEN
    cells[grid.walls] = OCCUPIED
    header = message.header
    return OccupancyGrid(
        header=Header(stamp=header.stamp, frame_id=header.frame_id),
        info=MapMetaData(map_load_time=header.stamp, resolution=resolution, width=columns,
                         height=rows,
                         origin=Pose(position=Point(x=grid.origin_x, y=grid.origin_y, z=0.0),
                                     orientation=Quaternion(x=0.0, y=0.0, z=0.0, w=1.0))),
        data=cells.reshape(-1))


def _finite(values: np.ndarray, width: int) -> np.ndarray:
    """Rows of ``width`` numbers from a flat array, rows with a non-finite number left out."""
    rows = values[:len(values) // width * width].reshape(-1, width)
    kept: np.ndarray = rows[np.isfinite(rows).all(axis=1)]
    return kept


def _fill(grid: MapGrid, outline: np.ndarray) -> None:
    """Mark the forbidden cells whose centres lie inside an area's outline, and the outline.

    Inside by the even-odd rule, for the cells of the outline's bounding box only.
    """
    low_rows, low_columns = grid.cells_of(outline.min(axis=0, keepdims=True))
    high_rows, high_columns = grid.cells_of(outline.max(axis=0, keepdims=True))
    rows, columns = np.mgrid[low_rows[0]:high_rows[0] + 1, low_columns[0]:high_columns[0] + 1]
    x = grid.origin_x + (columns + 0.5) * grid.resolution
    y = grid.origin_y + (rows + 0.5) * grid.resolution
    inside = np.zeros(x.shape, bool)
    for (x1, y1), (x2, y2) in zip(outline, np.roll(outline, -1, axis=0), strict=True):
        if y1 == y2:
            continue
        crosses = ((y1 > y) != (y2 > y)) & (x < x1 + (y - y1) * (x2 - x1) / (y2 - y1))
        inside ^= crosses
    grid.forbidden[rows[inside], columns[inside]] = True
    edges = np.hstack([outline, np.roll(outline, -1, axis=0)])
    grid.mark_segments(grid.forbidden, edges)
