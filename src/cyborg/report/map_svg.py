"""The path a robot drove, on its map, as one inline SVG.

Drawn from the recorded ``map_geometry`` (the latest one: a map switch draws the map the run
ended on) in the map frame, metres, x to the right and y up (the SVG's y is the map's -y), as
the monitor's map draws it: scanned points grey, walls dark, forbidden lines and areas red,
goals teal with their names, docks purple, home green; then the trajectory from ``pose``, its
start and end marked, and the goals driven to, coloured by how they ended.

Kept small whatever the map: the scanned points are merged into grid cells (at the map's
resolution, coarsened until at most :data:`MAX_POINT_CELLS` remain; columbia.map's 63,311
points become a few thousand cells), each one short path segment, and the trajectory keeps a
point only once the robot moved :data:`TRAJECTORY_STEP` from the last one kept, at most
:data:`MAX_TRAJECTORY_POINTS` in all.
"""

from __future__ import annotations

from collections.abc import Sequence
from html import escape
from typing import Any

import numpy as np

from cyborg.bus.msgs.cyborg_msgs.msg import MapObject
from cyborg.report.goals import GoalAttempt
from cyborg.report.svg import number

MAX_POINT_CELLS = 12000
"""The most grid cells of scanned points a map keeps."""
TRAJECTORY_STEP = 0.05
"""Metres the robot must move before the trajectory keeps another point."""
MAX_TRAJECTORY_POINTS = 5000
MARGIN = 1.0
"""Metres of room around what is drawn."""
_FORBIDDEN = (MapObject.FORBIDDEN_LINE, MapObject.FORBIDDEN_AREA)
_MARKED = {MapObject.GOAL: "goal", MapObject.GOAL_WITH_HEADING: "goal", MapObject.DOCK: "dock",
           MapObject.HOME: "home"}


def trajectory_points(poses: Sequence[tuple[float, float]]) -> list[tuple[float, float]]:
    """The trajectory as drawn: see the module (the last pose is always kept)."""
    kept: list[tuple[float, float]] = []
    for x, y in poses:
        if not (np.isfinite(x) and np.isfinite(y)):
            continue
        if kept and (x - kept[-1][0]) ** 2 + (y - kept[-1][1]) ** 2 < TRAJECTORY_STEP ** 2:
            continue
        kept.append((x, y))
    finite = [(x, y) for x, y in poses if np.isfinite(x) and np.isfinite(y)]
    if finite and kept and kept[-1] != finite[-1]:
        kept.append(finite[-1])
    if len(kept) > MAX_TRAJECTORY_POINTS:
        stride = -(-len(kept) // MAX_TRAJECTORY_POINTS)
        kept = kept[::stride] + ([kept[-1]] if (len(kept) - 1) % stride else [])
    return kept


def point_cells(points: np.ndarray, resolution: float) -> tuple[np.ndarray, float]:
    """The scanned points (``x y`` pairs, flat) merged into grid cells: (cell corners, size)."""
    pairs = np.asarray(points, np.float64).reshape(-1, 2)
    pairs = pairs[np.isfinite(pairs).all(axis=1)]
    size = resolution if resolution > 0 else 0.05
    while True:
        cells = np.unique(np.floor(pairs / size).astype(np.int64), axis=0)
        if len(cells) <= MAX_POINT_CELLS:
            return cells.astype(np.float64) * size, size
        size *= 2


def map_svg(geometry: Any | None, poses: Sequence[tuple[float, float]],
            goals: Sequence[GoalAttempt]) -> str:
    """The SVG of ``geometry`` (a MapGeometry, or None), the trajectory and the goals."""
    path = trajectory_points(poses)
    lines = np.asarray(geometry.lines, np.float64).reshape(-1, 4) if geometry is not None \
        else np.zeros((0, 4))
    lines = lines[np.isfinite(lines).all(axis=1)]
    cells, size = point_cells(geometry.points, float(geometry.resolution)) \
        if geometry is not None else (np.zeros((0, 2)), 0.05)
    objects = list(geometry.objects) if geometry is not None else []
    xs = [*lines[:, 0], *lines[:, 2], *cells[:, 0], *(x for x, _ in path),
          *(o.pose.x for o in objects)]
    ys = [*lines[:, 1], *lines[:, 3], *cells[:, 1], *(y for _, y in path),
          *(o.pose.y for o in objects)]
    finite = [(x, y) for x, y in zip(xs, ys, strict=True) if np.isfinite(x) and np.isfinite(y)]
    if not finite:
        return ""
    low_x = min(x for x, _ in finite) - MARGIN
    high_x = max(x for x, _ in finite) + MARGIN
    low_y = min(y for _, y in finite) - MARGIN
    high_y = max(y for _, y in finite) + MARGIN
    width, height = high_x - low_x, high_y - low_y
    scale = max(width, height) / 100.0  # strokes and labels as a share of the map's size
    parts = [f'<svg class="map" viewBox="{number(low_x)} {number(-high_y)} {number(width)} '
             f'{number(height)}" role="img" aria-label="map and trajectory" '
             f'style="--unit:{number(scale, 3)}px">']
    if len(cells):
        segments = "".join(f"M{number(x)} {number(-(y + size))}h{number(size)}"
                           for x, y in cells.tolist())
        parts.append(f'<path class="points" data-cells="{len(cells)}" '
                     f'stroke-width="{number(size, 3)}" d="{segments}"/>')
    if len(lines):
        walls = "".join(f"M{number(x1)} {number(-y1)}L{number(x2)} {number(-y2)}"
                        for x1, y1, x2, y2 in lines.tolist())
        parts.append(f'<path class="walls" stroke-width="{number(scale * 0.25, 3)}" '
                     f'd="{walls}"/>')
    parts += [_object(item, scale) for item in objects]
    if path:
        text = " ".join(f"{number(x)},{number(-y)}" for x, y in path)
        parts.append(f'<polyline class="trajectory" data-points="{len(path)}" '
                     f'stroke-width="{number(scale * 0.35, 3)}" points="{text}"/>')
        for (x, y), which in ((path[0], "start"), (path[-1], "end")):
            parts.append(f'<circle class="{which}" cx="{number(x)}" cy="{number(-y)}" '
                         f'r="{number(scale * 0.9, 3)}"><title>{which}</title></circle>')
    for attempt in goals:
        if attempt.position is None:
            continue
        x, y = attempt.position
        parts.append(f'<circle class="attempt {attempt.outcome.value}" cx="{number(x)}" '
                     f'cy="{number(-y)}" r="{number(scale * 1.2, 3)}"><title>'
                     f'{escape(attempt.name)}: {attempt.outcome.value}</title></circle>')
    parts.append("</svg>")
    return "".join(parts)


def _object(item: Any, scale: float) -> str:
    category = int(item.category)
    outline = np.asarray(item.outline, np.float64).reshape(-1, 2)
    if category in _FORBIDDEN and len(outline) >= 2:
        shape = "polyline" if category == MapObject.FORBIDDEN_LINE else "polygon"
        text = " ".join(f"{number(x)},{number(-y)}" for x, y in outline.tolist())
        return (f'<{shape} class="forbidden" stroke-width="{number(scale * 0.3, 3)}" '
                f'points="{text}"/>')
    kind = _MARKED.get(category)
    if kind is None:
        return ""
    x, y = float(item.pose.x), float(item.pose.y)
    if not (np.isfinite(x) and np.isfinite(y)):
        return ""
    name = escape(str(item.name))
    return (f'<g class="{kind}"><circle cx="{number(x)}" cy="{number(-y)}" '
            f'r="{number(scale * 0.6, 3)}"/><text x="{number(x + scale)}" y="{number(-y)}" '
            f'font-size="{number(scale * 2.2, 3)}">{name}</text></g>')
