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
footprint      ``[x0, y0, x1, y1, ...]``: the robot's outline in its own frame, m (1 mm)
transforms     ``{child: (parent, [x, y, θ])}`` from ``/tf_static``; :func:`mount_of` chains them
               into the laser's mount on the robot, ``[x, y, θ]`` (m, rad; 1 mm, 1 mrad)
current goal   ``{"name", "p": [x, y, θ], "h"}``: the goal's name, where it is (as a pose) and
               whether the robot turns to its heading there; None when there is no goal
=============  ==================================================================================
"""

from __future__ import annotations

import json
import math
from typing import Any

import numpy as np

from cyborg.bus.msgs.cyborg_msgs.msg import BatteryStatus, GoalWithHeading
from cyborg.bus.msgs.geometry_msgs.msg import PolygonStamped, Pose2D
from cyborg.bus.msgs.nav_msgs.msg import Path
from cyborg.bus.msgs.sensor_msgs.msg import LaserScan
from cyborg.bus.msgs.tf2_msgs.msg import TFMessage
from cyborg.interfaces import robot

Warnings = list[str]

WORLD_LIMIT = 10_000.0
"""Farthest a pose, path point or map coordinate may lie from the origin, in metres."""
SCAN_BEAM_LIMIT = 8192
"""Most beams a scan may have to be drawn (a Pioneer LX's S300 has 541)."""
PATH_LIMIT = 20_000
"""Most poses of a path sent to the page; longer paths are thinned evenly."""
TEXT_LIMIT = 200
"""Longest text (dock state, path state, frame names) passed on, in characters."""
FOOTPRINT_LIMIT = 256
"""Most corners a footprint may have to be drawn (the Pioneer LX's has 12)."""
BODY_LIMIT = 100.0
"""Farthest a footprint corner or a fixed transform may reach from the robot's origin, in m."""
TRANSFORM_LIMIT = 256
"""Most transforms of one ``/tf_static`` message that are read."""
FRAMES_KEPT = 1024
"""Most child frames a robot's source remembers; beyond, it keeps only the latest message's."""
CHAIN_LIMIT = 16
"""Most transforms chained from the laser's frame up to the robot's (a loop ends there)."""

Mount = list[float]
"""``[x, y, θ]``: where a frame sits on the robot (m, rad)."""
Transforms = dict[str, tuple[str, Mount]]
"""Fixed transforms by child frame: ``{child: (parent, [x, y, θ])}``."""
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
    increment is 0 or more than a full turn, with more than :data:`SCAN_BEAM_LIMIT` beams, or
    whose number of ranges is not ``round((angle_max - angle_min) / angle_increment) + 1``
    (±1).
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
    if abs(increment) > math.tau:
        return None, [f"scan: angle_increment is {_number(increment)} rad, more than a full "
                      "turn; scan not drawn"]
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
    return {"a0": round(_angle(angle_min), 6), "da": float(f"{increment:.9g}"),
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


def goal_wire(message: GoalWithHeading) -> tuple[dict[str, Any] | None, Warnings]:
    """The current goal as ``{"name", "p": [x, y, θ], "h"}``; None when there is none.

    An empty ``name`` says the robot drives to no goal (None, no warning). A goal whose position
    is not finite or lies more than :data:`WORLD_LIMIT` m away is not shown either, with a
    warning; the name is clipped to :data:`TEXT_LIMIT` characters.
    """
    name, clipped = clip_text(message.name)
    if not name:
        return None, []
    position, problems = pose_wire(message.position)
    if position is None:
        problem = problems[0].removeprefix("pose: ").removesuffix("; last good pose kept")
        return None, [f"goal: {name[:40]!r} not shown: {problem}"]
    warnings: Warnings = []
    if clipped:
        warnings.append(f"goal: name clipped to {TEXT_LIMIT} characters")
    return {"name": name, "p": position, "h": bool(message.has_heading)}, warnings


def footprint_wire(message: PolygonStamped) -> tuple[list[float] | None, Warnings]:
    """The outline as ``[x0, y0, x1, y1, ...]`` (m, 1 mm); None with a warning when unusable.

    An outline needs 3 to :data:`FOOTPRINT_LIMIT` corners, all finite and within
    :data:`BODY_LIMIT` m of the robot's origin; otherwise the page keeps the one it has (the
    Pioneer LX's until a good one comes).
    """
    corners = message.polygon.points
    if not 3 <= len(corners) <= FOOTPRINT_LIMIT:
        return None, [f"footprint: {len(corners):,} corners, not 3 to {FOOTPRINT_LIMIT}; "
                      "footprint not drawn"]
    xy = np.array([(float(corner.x), float(corner.y)) for corner in corners], np.float64)
    with np.errstate(invalid="ignore"):
        bad = ~(np.isfinite(xy) & (np.abs(xy) <= BODY_LIMIT))
    if bad.any():
        return None, [f"footprint: {_number(float(xy[bad][0]))} m is not a corner within "
                      f"{BODY_LIMIT:g} m; footprint not drawn"]
    return [round(float(value), 3) for value in xy.reshape(-1)], []


def transforms_wire(message: TFMessage) -> tuple[Transforms, Warnings]:
    """The transforms of a ``/tf_static`` message as ``{child: (parent, [x, y, θ])}``.

    Only the plane matters to the map (z, roll and pitch are left out). A transform with a
    value that is not finite, or more than :data:`BODY_LIMIT` m long, is left out with a
    warning; so is everything past the first :data:`TRANSFORM_LIMIT`.
    """
    found: Transforms = {}
    warnings: Warnings = []
    transforms = message.transforms
    if len(transforms) > TRANSFORM_LIMIT:
        warnings.append(f"tf: {len(transforms):,} transforms in one message; the first "
                        f"{TRANSFORM_LIMIT} read")
    for stamped in transforms[:TRANSFORM_LIMIT]:
        child, _clipped = clip_text(stamped.child_frame_id)
        parent, _clipped = clip_text(stamped.header.frame_id)
        shift, turn = stamped.transform.translation, stamped.transform.rotation
        x, y = float(shift.x), float(shift.y)
        rotation = (float(turn.x), float(turn.y), float(turn.z), float(turn.w))
        if not all(_finite(value) for value in (x, y, *rotation)) \
                or abs(x) > BODY_LIMIT or abs(y) > BODY_LIMIT:
            warnings.append(f"tf: the transform {parent!r} -> {child!r} is not finite or longer "
                            f"than {BODY_LIMIT:g} m; left out")
            continue
        found[child] = (parent, [x, y, robot.yaw_of(*rotation)])
    return found, warnings


def mount_of(frame: str, transforms: Transforms) -> Mount | None:
    """Where ``frame`` sits on the robot, ``[x, y, θ]`` (1 mm, 1 mrad), or None if unknown.

    The transforms are chained from ``frame`` up through its parents for as long as each parent
    is itself some frame's child (at most :data:`CHAIN_LIMIT` steps); the last parent is the
    robot's frame (``base_link`` for the simulator).
    """
    if frame not in transforms:
        return None
    x = y = theta = 0.0
    seen: set[str] = set()
    while frame in transforms and frame not in seen and len(seen) < CHAIN_LIMIT:
        seen.add(frame)
        frame, (px, py, ptheta) = transforms[frame]
        cos, sin = math.cos(ptheta), math.sin(ptheta)
        x, y, theta = px + cos * x - sin * y, py + sin * x + cos * y, ptheta + theta
    return [round(x, 3), round(y, 3), round(_angle(theta), 3)]
