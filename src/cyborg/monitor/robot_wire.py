"""A robot's topics as the page's map panel gets them: small JSON, checked, never NaN.

Pure functions, one per topic, each returning ``(payload, warnings)``: the payload is None when
the message cannot be drawn at all (the page keeps what it had), and each warning is one line
for the page's warning list, starting with the topic it concerns. None of them raises on any
value a message can carry (NaN, infinities, huge numbers, wrong lengths); every text the
monitor sends is encoded with :func:`wire_text`, which refuses NaN and infinities.

=============  ==================================================================================
payload        shape
=============  ==================================================================================
pose           ``[x, y, θ]``: m and rad, rounded to 1 mm and 1 mrad, θ in [-π, π]
scan           ``{"a0", "da", "mx", "r"}``: first angle and increment (rad), range_max (mm), the
               ranges in whole mm, where ``0`` is no return (+Inf, beyond range_max) and ``-1``
               an invalid reading (NaN, -Inf, below range_min)
path           ``{"xy": [x0, y0, x1, y1, ...]}`` in whole mm, at most :data:`PATH_LIMIT` poses
battery        ``{"pct", "charging", "dock"}``: charge 0-100 (0.1), whether charging, the dock
               state's text
path state     the text of ``arnl_path_state``
=============  ==================================================================================
"""

from __future__ import annotations

import json
import math
from typing import Any

import numpy as np

from cyborg.bus.msgs.cyborg_msgs.msg import BatteryStatus
from cyborg.bus.msgs.geometry_msgs.msg import Pose2D
from cyborg.bus.msgs.nav_msgs.msg import Path
from cyborg.bus.msgs.sensor_msgs.msg import LaserScan

Warnings = list[str]

WORLD_LIMIT = 10_000.0
"""Farthest a pose, path point or map coordinate may lie from the origin, in metres."""
SCAN_BEAM_LIMIT = 8192
"""Most beams a scan may have to be drawn (a Pioneer LX's S300 has 541)."""
PATH_LIMIT = 20_000
"""Most poses of a path sent to the page; longer paths are thinned evenly."""
TEXT_LIMIT = 200
"""Longest text (dock state, path state) passed on, in characters."""
_MM = 1000.0


def wire_text(message: dict[str, Any]) -> str:
    """Compact JSON text of a message to the pages; ``ValueError`` for NaN or infinities."""
    return json.dumps(message, separators=(",", ":"), allow_nan=False)


def _finite(value: float) -> bool:
    return math.isfinite(value)


def _number(value: float) -> str:
    """A number as a warning shows it: ``nan``, ``inf``, ``1e+12`` or ``3.25``."""
    return f"{value:.6g}"


def _angle(value: float) -> float:
    """``value`` (finite, rad) wrapped into [-π, π]."""
    return math.remainder(value, math.tau)


def clip_text(value: object, limit: int = TEXT_LIMIT) -> tuple[str, bool]:
    """``value`` as text of at most ``limit`` characters, and whether it was clipped."""
    text = value if isinstance(value, str) else str(value)
    return (text, False) if len(text) <= limit else (text[:limit], True)


def pose_wire(message: Pose2D) -> tuple[list[float] | None, Warnings]:
    """The pose as ``[x, y, θ]`` (1 mm, 1 mrad); None with a warning when it is unusable.

    A pose with a NaN or infinite field, or more than :data:`WORLD_LIMIT` m from the origin, is
    dropped: the page keeps the last good one.
    """
    values = {"x": float(message.x), "y": float(message.y), "theta": float(message.theta)}
    for name, value in values.items():
        if not _finite(value):
            return None, [f"pose: {name} is {_number(value)}; last good pose kept"]
    x, y = values["x"], values["y"]
    if abs(x) > WORLD_LIMIT or abs(y) > WORLD_LIMIT:
        return None, [f"pose: ({_number(x)}, {_number(y)}) is more than "
                      f"{WORLD_LIMIT / 1000:g} km from the origin; last good pose kept"]
    return [round(x, 3), round(y, 3), round(_angle(values["theta"]), 3)], []


def scan_wire(message: LaserScan) -> tuple[dict[str, Any] | None, Warnings]:
    """The scan as ``{"a0", "da", "mx", "r"}`` (see the module docstring), or None.

    Refused with a warning: a scan whose angles or ``range_max`` are not finite, whose
    increment is 0, with more than :data:`SCAN_BEAM_LIMIT` beams, or whose number of ranges is
    not ``round((angle_max - angle_min) / angle_increment) + 1`` (±1).
    """
    angle_min, angle_max = float(message.angle_min), float(message.angle_max)
    increment = float(message.angle_increment)
    range_min, range_max = float(message.range_min), float(message.range_max)
    ranges = np.asarray(message.ranges).reshape(-1)
    beams = int(ranges.size)
    for name, value in (("angle_min", angle_min), ("angle_max", angle_max),
                        ("angle_increment", increment), ("range_max", range_max)):
        if not _finite(value):
            return None, [f"scan: {name} is {_number(value)}; scan not drawn"]
    if increment == 0.0:
        return None, ["scan: angle_increment is 0; scan not drawn"]
    if not 0.0 < range_max <= WORLD_LIMIT:
        return None, [f"scan: range_max is {_number(range_max)} m; scan not drawn"]
    if beams > SCAN_BEAM_LIMIT:
        return None, [f"scan: {beams:,} beams, more than the {SCAN_BEAM_LIMIT:,} the monitor "
                      "draws; scan not drawn"]
    span = (angle_max - angle_min) / increment
    expected = round(span) + 1 if _finite(span) and abs(span) <= 4 * SCAN_BEAM_LIMIT else None
    if expected is None or abs(beams - expected) > 1:
        said = f"{expected:,}" if expected is not None else "far more"
        return None, [f"scan: {beams:,} ranges where angle_min, angle_max and angle_increment "
                      f"make {said}; scan not drawn"]
    if not _finite(range_min) or range_min < 0.0:
        range_min = 0.0
    values = ranges.astype(np.float64, copy=False)
    with np.errstate(invalid="ignore", over="ignore"):
        seen = (values >= range_min) & (values <= range_max)  # False for NaN
        invalid = np.isnan(values) | (values < range_min)  # -Inf too
        millimetres = np.zeros(beams, np.int64)
        millimetres[seen] = np.maximum(np.rint(values[seen] * _MM), 1)
        millimetres[invalid] = -1
    return {"a0": round(_angle(angle_min), 6), "da": round(increment, 9),
            "mx": round(range_max * _MM), "r": millimetres.tolist()}, []


def path_wire(message: Path) -> tuple[dict[str, Any], Warnings]:
    """The path as ``{"xy": [...]}`` in whole mm, thinned to at most :data:`PATH_LIMIT` poses.

    Poses that are not finite or lie more than :data:`WORLD_LIMIT` m from the origin are left
    out, with a warning; a longer path keeps its first and last poses and every n-th between.
    """
    poses = message.poses
    count = len(poses)
    warnings: Warnings = []
    if count > PATH_LIMIT:
        indices = np.unique(np.rint(np.linspace(0, count - 1, PATH_LIMIT)).astype(np.int64))
        warnings.append(f"path: {count:,} poses, thinned to {len(indices):,} for the page")
    else:
        indices = np.arange(count)
    xy = np.empty((len(indices), 2), np.float64)
    for row, index in enumerate(indices.tolist()):
        position = poses[index].pose.position
        xy[row] = (float(position.x), float(position.y))
    with np.errstate(invalid="ignore"):
        good = np.isfinite(xy).all(axis=1) & (np.abs(xy) <= WORLD_LIMIT).all(axis=1)
    dropped = int(len(xy) - np.count_nonzero(good))
    if dropped:
        warnings.append(f"path: {dropped:,} poses are not finite or lie more than "
                        f"{WORLD_LIMIT / 1000:g} km away; left out")
    return {"xy": np.rint(xy[good] * _MM).astype(np.int64).reshape(-1).tolist()}, warnings


def battery_wire(message: BatteryStatus) -> tuple[dict[str, Any] | None, Warnings]:
    """The battery as ``{"pct", "charging", "dock"}``; None when the charge is not a number.

    The charge is clamped to 0-100 % (with a warning when it was outside), the dock state
    clipped to :data:`TEXT_LIMIT` characters.
    """
    charge = float(message.charge_percent)
    if not _finite(charge):
        return None, [f"battery: charge_percent is {_number(charge)}; battery not shown"]
    warnings: Warnings = []
    if not 0.0 <= charge <= 100.0:
        warnings.append(f"battery: charge {_number(charge)} % clamped to 0-100")
        charge = min(100.0, max(0.0, charge))
    dock, clipped = clip_text(message.dock_state)
    if clipped:
        warnings.append(f"battery: dock_state clipped to {TEXT_LIMIT} characters")
    return {"pct": round(charge, 1), "charging": bool(message.charging), "dock": dock}, warnings


def state_wire(text: str) -> tuple[str, Warnings]:
    """The path state's text, clipped to :data:`TEXT_LIMIT` characters (with a warning)."""
    state, clipped = clip_text(text)
    return state, [f"state: arnl_path_state clipped to {TEXT_LIMIT} characters"] if clipped else []
