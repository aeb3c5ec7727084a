"""Other robots' bodies as obstacles: outlines in the map, gaps between bodies, laser hits.

When several simulated robots share a map (:mod:`cyborg.sim.fleet`), each robot's outline is
an obstacle to the others, exactly as drawn: a convex polygon (the footprint of
:meth:`cyborg.nav.footprint.Footprint.polygon`) placed at the robot's pose by :func:`outline_at`.

* :func:`polygon_gap` is the smallest distance between two such outlines, negative (minus the
  depth of the overlap) when they overlap; the drive refuses a step that makes it negative.
* :func:`cast_onto` shortens laser beams that hit an outline before anything else;
  :func:`cast_onto_circles` those that hit a round body (a walking person,
  :mod:`cyborg.sim.people`).
* :func:`outline_points` samples an outline as points, which the motion check and the
  navigator take like laser returns (so a robot knows of another even behind its back, where
  the laser is blind); :func:`braking_outline` samples the outline of the ground a moving
  robot covers along its braking way (:func:`braking_poses`), so that two robots driving at
  each other each keep out of the other's way, not only out of where it is now.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numba import njit

from cyborg.nav.geometry import Pose2D

OUTLINE_SPACING = 0.05
"""Metres between the points :func:`outline_points` puts on an outline."""


def outline_at(polygon: np.ndarray, pose: Pose2D) -> np.ndarray:
    """``polygon`` (K x 2, in the robot's frame) placed at ``pose``: K x 2 map coordinates."""
    return _placed(np.ascontiguousarray(polygon, dtype=np.float64), pose.x, pose.y, pose.theta)


@njit(cache=True)
def _placed(polygon: np.ndarray, x: float, y: float,
            theta: float) -> np.ndarray:  # pragma: no cover - jit
    cos, sin = math.cos(theta), math.sin(theta)
    out = np.empty_like(polygon)
    for k in range(polygon.shape[0]):
        out[k, 0] = x + cos * polygon[k, 0] - sin * polygon[k, 1]
        out[k, 1] = y + sin * polygon[k, 0] + cos * polygon[k, 1]
    return out


def nearest_gap(outline: np.ndarray, others: Sequence[np.ndarray]) -> float:
    """The smallest :func:`polygon_gap` between ``outline`` and any of ``others`` (inf: none)."""
    lowest = math.inf
    for other in others:
        lowest = min(lowest, float(polygon_gap(outline, other)))
    return lowest


@njit(cache=True)
def outline_bounds(corners: np.ndarray,
                   starts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:  # pragma: no cover
    """Centres ((N, 2): the corners' mean) and radii (N) of circles around N outlines.

    The outlines lie one after the other in ``corners``; outline ``n`` is rows
    ``starts[n]`` to ``starts[n + 1]`` (``starts`` has N + 1 entries).
    """
    count = starts.shape[0] - 1
    middles, radii = np.zeros((count, 2)), np.zeros(count)
    for n in range(count):
        size = starts[n + 1] - starts[n]
        for k in range(starts[n], starts[n + 1]):
            middles[n, 0] += corners[k, 0] / size
            middles[n, 1] += corners[k, 1] / size
        for k in range(starts[n], starts[n + 1]):
            radii[n] = max(radii[n], math.hypot(corners[k, 0] - middles[n, 0],
                                                corners[k, 1] - middles[n, 1]))
    return middles, radii


@njit(cache=True)
def gap_below(body: np.ndarray, reach: float, corners: np.ndarray, starts: np.ndarray,
              middles: np.ndarray, radii: np.ndarray,
              below: float) -> float:  # pragma: no cover - jit
    """The smallest :func:`polygon_gap` from ``body`` to outlines nearer than ``below`` m.

    Inf when none may be nearer. ``body`` is K x 2 map corners whose circle of radius
    ``reach`` around their mean holds them; the outlines are as :func:`outline_bounds` takes
    them, with its circles: an outline whose circle is ``below`` or further from the body's
    circle is not measured.
    """
    cx, cy = 0.0, 0.0
    for k in range(body.shape[0]):
        cx += body[k, 0] / body.shape[0]
        cy += body[k, 1] / body.shape[0]
    lowest = np.inf
    for n in range(starts.shape[0] - 1):
        if math.hypot(middles[n, 0] - cx, middles[n, 1] - cy) - radii[n] - reach >= below:
            continue
        lowest = min(lowest, polygon_gap(body, corners[starts[n]:starts[n + 1]]))
    return lowest


@njit(cache=True)
def polygon_gap(a: np.ndarray, b: np.ndarray) -> float:  # pragma: no cover - jit
    """The gap (m) between convex polygons ``a`` and ``b`` (K x 2 corners, in order).

    Apart, it is their distance; overlapping, it is minus the smallest shift along an edge's
    normal that would part them (separating axes). Touching gives 0.
    """
    depth = np.inf
    for polygon in (a, b):
        count = polygon.shape[0]
        for i in range(count):
            j = (i + 1) % count
            nx = polygon[j, 1] - polygon[i, 1]
            ny = polygon[i, 0] - polygon[j, 0]
            norm = math.hypot(nx, ny)
            if norm == 0.0:
                continue
            nx, ny = nx / norm, ny / norm
            low_a = high_a = a[0, 0] * nx + a[0, 1] * ny
            for k in range(1, a.shape[0]):
                value = a[k, 0] * nx + a[k, 1] * ny
                low_a, high_a = min(low_a, value), max(high_a, value)
            low_b = high_b = b[0, 0] * nx + b[0, 1] * ny
            for k in range(1, b.shape[0]):
                value = b[k, 0] * nx + b[k, 1] * ny
                low_b, high_b = min(low_b, value), max(high_b, value)
            overlap = min(high_a, high_b) - max(low_a, low_b)
            if overlap < 0.0:  # a separating axis: the distance is between corners and edges
                return min(_corner_distance(a, b), _corner_distance(b, a))
            depth = min(depth, overlap)
    return -depth


@njit(cache=True)
def _corner_distance(corners: np.ndarray, polygon: np.ndarray) -> float:  # pragma: no cover
    best = np.inf
    count = polygon.shape[0]
    for k in range(corners.shape[0]):
        px, py = corners[k, 0], corners[k, 1]
        for i in range(count):
            j = (i + 1) % count
            ax, ay = polygon[i, 0], polygon[i, 1]
            dx, dy = polygon[j, 0] - ax, polygon[j, 1] - ay
            length = dx * dx + dy * dy
            t = 0.0 if length == 0.0 else max(0.0, min(1.0, ((px - ax) * dx + (py - ay) * dy)
                                                       / length))
            best = min(best, math.hypot(px - ax - t * dx, py - ay - t * dy))
    return best


@njit(cache=True)
def cast_onto(outline: np.ndarray, x: float, y: float, angles: np.ndarray,
              ranges: np.ndarray) -> None:  # pragma: no cover - jit
    """Shorten ``ranges`` (m, from ``(x, y)`` along absolute ``angles``) that hit ``outline``.

    Beams that pass the circle around the outline, or end before it, are not tried.
    """
    count = outline.shape[0]
    cx, cy, radius = 0.0, 0.0, 0.0
    for k in range(count):
        cx += outline[k, 0] / count
        cy += outline[k, 1] / count
    for k in range(count):
        radius = max(radius, math.hypot(outline[k, 0] - cx, outline[k, 1] - cy))
    cx, cy, radius = cx - x, cy - y, radius + 1e-9
    for beam in range(angles.shape[0]):
        dx, dy = math.cos(angles[beam]), math.sin(angles[beam])
        along = dx * cx + dy * cy
        if along < -radius or along - radius > ranges[beam] or abs(dx * cy - dy * cx) > radius:
            continue
        for i in range(count):
            j = (i + 1) % count
            ax, ay = outline[i, 0] - x, outline[i, 1] - y
            ex, ey = outline[j, 0] - outline[i, 0], outline[j, 1] - outline[i, 1]
            denominator = dx * ey - dy * ex
            if denominator == 0.0:
                continue  # parallel to the edge
            along = (ax * ey - ay * ex) / denominator  # distance along the beam
            share = (ax * dy - ay * dx) / denominator  # where on the edge, 0..1
            if along >= 0.0 and 0.0 <= share <= 1.0 and along < ranges[beam]:
                ranges[beam] = along


@njit(cache=True)
def cast_onto_fan(outline: np.ndarray, x: float, y: float, first: float, increment: float,
                  ranges: np.ndarray) -> None:  # pragma: no cover - jit
    """:func:`cast_onto` for a laser's evenly spaced beams, ``first + k increment``.

    Only the beams within the angular width of the circle around the outline are tried.
    """
    count = outline.shape[0]
    cx, cy, radius = 0.0, 0.0, 0.0
    for k in range(count):
        cx += outline[k, 0] / count
        cy += outline[k, 1] / count
    for k in range(count):
        radius = max(radius, math.hypot(outline[k, 0] - cx, outline[k, 1] - cy))
    distance = math.hypot(cx - x, cy - y)
    beams = ranges.shape[0]
    if distance <= radius + 1e-9:  # the scanner within its circle: every beam
        low, high = 0, beams - 1
    else:
        half = math.asin(min(1.0, (radius + 1e-9) / distance))
        offset = (math.atan2(cy - y, cx - x) - half - first) % (2.0 * math.pi)
        low = math.ceil(offset / increment)
        high = math.floor((offset + 2.0 * half) / increment)
    turn = round(2.0 * math.pi / increment)
    for step in range(low, high + 1):
        beam = step
        if beam >= beams:
            beam -= turn  # a scan wider than it is long
            if beam < 0 or beam >= beams:
                continue
        angle = first + beam * increment
        dx, dy = math.cos(angle), math.sin(angle)
        for i in range(count):
            j = (i + 1) % count
            ax, ay = outline[i, 0] - x, outline[i, 1] - y
            ex, ey = outline[j, 0] - outline[i, 0], outline[j, 1] - outline[i, 1]
            denominator = dx * ey - dy * ex
            if denominator == 0.0:
                continue
            along = (ax * ey - ay * ex) / denominator
            share = (ax * dy - ay * dx) / denominator
            if along >= 0.0 and 0.0 <= share <= 1.0 and along < ranges[beam]:
                ranges[beam] = along


@njit(cache=True)
def cast_onto_circles(circles: np.ndarray, x: float, y: float, first: float, increment: float,
                      ranges: np.ndarray) -> None:  # pragma: no cover - jit
    """Shorten ``ranges`` whose beams hit one of ``circles`` ((N, 3): x, y, radius; m).

    The beams leave ``(x, y)`` at the absolute angles ``first + k increment``. Only the beams
    within a circle's angular width are tried, so many people cost the laser little.
    """
    beams = ranges.shape[0]
    for index in range(circles.shape[0]):
        cx, cy, radius = circles[index, 0] - x, circles[index, 1] - y, circles[index, 2]
        distance = math.hypot(cx, cy)
        if distance <= radius:
            continue  # the scanner inside a body: it sees nothing of it
        bearing = math.atan2(cy, cx)
        half = math.asin(radius / distance)
        offset = (bearing - half - first) % (2.0 * math.pi)
        low = math.ceil(offset / increment)
        high = math.floor((offset + 2.0 * half) / increment)
        for step in range(low, high + 1):
            beam = step
            if beam >= beams:
                beam -= round(2.0 * math.pi / increment)  # a scan wider than it is long
                if beam < 0 or beam >= beams:
                    continue
            angle = first + beam * increment
            dx, dy = math.cos(angle), math.sin(angle)
            along = dx * cx + dy * cy
            aside = distance * distance - along * along
            if aside > radius * radius or along <= 0.0:
                continue
            hit = along - math.sqrt(radius * radius - aside)
            if 0.0 <= hit < ranges[beam]:
                ranges[beam] = hit


@njit(cache=True)
def cast_onto_circles_at(circles: np.ndarray, x: float, y: float, angles: np.ndarray,
                         ranges: np.ndarray) -> None:  # pragma: no cover - jit
    """Shorten ``ranges`` (from ``(x, y)`` along absolute ``angles``) that hit ``circles``.

    ``circles`` are (N, 3) rows of x, y, radius (m); for a few rays at any angles, where
    :func:`cast_onto_circles` serves a laser's evenly spaced beams.
    """
    for ray in range(angles.shape[0]):
        dx, dy = math.cos(angles[ray]), math.sin(angles[ray])
        for index in range(circles.shape[0]):
            cx, cy, radius = circles[index, 0] - x, circles[index, 1] - y, circles[index, 2]
            along = dx * cx + dy * cy
            aside = cx * cx + cy * cy - along * along
            if along <= 0.0 or aside > radius * radius:
                continue
            hit = along - math.sqrt(radius * radius - aside)
            if 0.0 <= hit < ranges[ray]:
                ranges[ray] = hit


KEEP_CLEAR = 0.1
"""Metres a robot's navigator and motion check keep from another robot's outline.

They hold the robot's own body as three circles (:meth:`~cyborg.nav.footprint.Footprint.
circles`), which leave its cut corners out by up to 6 cm: kept this much further off,
those corners do not touch the other robot either."""


def grown(polygon: np.ndarray, margin: float) -> np.ndarray:
    """The convex ``polygon`` with every edge moved ``margin`` m outwards.

    ``polygon`` is K x 2 corners, counter-clockwise; the new corners are mitred.
    """
    following = np.roll(polygon, -1, axis=0) - polygon
    normals = np.column_stack([following[:, 1], -following[:, 0]])
    normals /= np.maximum(np.hypot(normals[:, 0], normals[:, 1]), 1e-12)[:, None]
    before = np.roll(normals, 1, axis=0)  # the normal of the edge ending at each corner
    mitre = (normals + before) / (1.0 + np.sum(normals * before, axis=1))[:, None]
    result: np.ndarray = polygon + margin * mitre
    return result


def outline_points(outline: np.ndarray, spacing: float = OUTLINE_SPACING) -> np.ndarray:
    """Points along ``outline``'s edges, at most ``spacing`` apart: (N, 2) map coordinates."""
    pieces = []
    for start, end in zip(outline, np.roll(outline, -1, axis=0), strict=True):
        steps = max(1, math.ceil(float(np.hypot(*(end - start))) / spacing))
        share = np.arange(steps)[:, None] / steps
        pieces.append(start + share * (end - start))
    return np.concatenate(pieces) if pieces else np.zeros((0, 2))


BRAKING_STEP = 0.25
"""Metres between the poses :func:`braking_poses` puts along a robot's braking way."""


def braking_poses(pose: Pose2D, speed: float, deceleration: float) -> list[Pose2D]:
    """Where a robot at ``pose`` will be until it stops, braking from ``speed`` (m/s).

    It brakes straight ahead (backwards for a negative speed) at ``deceleration`` (m/s²): the
    pose where it stands, and when it moves more along the way, :data:`BRAKING_STEP` apart.
    """
    way = speed * abs(speed) / (2.0 * deceleration)
    steps = math.ceil(abs(way) / BRAKING_STEP)
    cos, sin = math.cos(pose.theta), math.sin(pose.theta)
    return [pose] + [Pose2D(pose.x + cos * way * k / steps, pose.y + sin * way * k / steps,
                            pose.theta) for k in range(1, steps + 1)]


def placed(points: np.ndarray, poses: list[Pose2D]) -> np.ndarray:
    """``points`` (N x 2, in the robot's frame) placed at each of ``poses``: (len(poses) N, 2)."""
    theta = np.array([pose.theta for pose in poses])[:, None]
    x = np.array([pose.x for pose in poses])[:, None]
    y = np.array([pose.y for pose in poses])[:, None]
    cos, sin = np.cos(theta), np.sin(theta)
    px, py = points[:, 0][None, :], points[:, 1][None, :]
    return np.column_stack([(x + cos * px - sin * py).ravel(), (y + sin * px + cos * py).ravel()])


def braking_outline(polygon: np.ndarray, pose: Pose2D, speed: float, deceleration: float,
                    spacing: float = OUTLINE_SPACING,
                    sides: tuple[np.ndarray, np.ndarray] | None = None) -> np.ndarray:
    """Points along the outline of the ground a robot covers until it stands, braking straight.

    ``polygon`` (K x 2, convex, counter-clockwise, in the robot's frame) swept along the
    braking way of :func:`braking_poses` (at ``speed`` m/s, braking at ``deceleration``
    m/s²) is the polygon with its front half moved forward by the way (its back half, when
    backing): the outline of every pose along the way at once, at most ``spacing`` apart.
    ``sides``: the polygon's :func:`halves`, when known.
    """
    way = speed * abs(speed) / (2.0 * deceleration)
    swept = np.array(polygon, dtype=np.float64)
    if way != 0.0:
        front, back = sides if sides is not None else halves(swept)
        swept[front if way > 0.0 else back, 0] += way
    return _along(outline_at(swept, pose), spacing)


def halves(polygon: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The corners of a convex counter-clockwise ``polygon`` on its front, and on its back."""
    return _leading(polygon, True), _leading(polygon, False)


def _leading(polygon: np.ndarray, forward: bool) -> np.ndarray:
    """The corners of ``polygon`` on its front (``forward``) or back, from bottom to top.

    Of a convex counter-clockwise polygon: those from its lowest corner to its highest going
    round its front (the rightmost of equally low ones to the rightmost of equally high ones);
    going round its back for the back. Moved along x, they and the rest outline the sweep.
    """
    ys, xs = polygon[:, 1], polygon[:, 0]
    count = len(polygon)
    low = min(range(count), key=lambda k: (ys[k], -xs[k] if forward else xs[k]))
    high = min(range(count), key=lambda k: (-ys[k], -xs[k] if forward else xs[k]))
    first, last = (low, high) if forward else (high, low)
    steps = (last - first) % count
    return np.array([(first + k) % count for k in range(steps + 1)], dtype=np.int64)


@njit(cache=True)
def _along(outline: np.ndarray, spacing: float) -> np.ndarray:  # pragma: no cover - jit
    """:func:`outline_points`, compiled."""
    count = outline.shape[0]
    total = 0
    for i in range(count):
        j = (i + 1) % count
        total += max(1, math.ceil(math.hypot(outline[j, 0] - outline[i, 0],
                                             outline[j, 1] - outline[i, 1]) / spacing))
    points = np.empty((total, 2))
    index = 0
    for i in range(count):
        j = (i + 1) % count
        dx, dy = outline[j, 0] - outline[i, 0], outline[j, 1] - outline[i, 1]
        steps = max(1, math.ceil(math.hypot(dx, dy) / spacing))
        for k in range(steps):
            points[index, 0] = outline[i, 0] + k / steps * dx
            points[index, 1] = outline[i, 1] + k / steps * dy
            index += 1
    return points
