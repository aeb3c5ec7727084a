"""Acting on the simulated robot by hand: where it may be put, and how fast it may be driven.

:func:`placement_problem` says whether the robot may be put at a pose (``set_pose``,
``/initialpose``): the pose must be finite, on the map (within the extent of its walls, points
and objects), and the body there must overlap neither a wall or obstacle (the simulated world's
clearance grid, as the bumpers feel it), nor another robot, nor a forbidden area or line.
:func:`limit_command` clamps a hand-given speed command (``cmd_vel``) to the teleoperation limits of
:mod:`cyborg.interfaces.robot` and the drive's own.
"""

from __future__ import annotations

import math

import numpy as np

from cyborg.interfaces.robot import TELEOP_MAX_SPEED, TELEOP_MAX_TURN_RATE
from cyborg.nav.geometry import Pose2D
from cyborg.nav.grid import MapGrid
from cyborg.sim.robot import DriveLimits, RobotBase


def placement_problem(pose: Pose2D, bounds: tuple[float, float, float, float],
                      base: RobotBase, world: MapGrid) -> str | None:
    """Why the robot cannot be put at ``pose``, or None if it can.

    ``bounds`` is the map's extent (``ArnlMap.bounds()``), ``base`` the robot (its body and the
    clearance grid of walls and obstacles), ``world`` the grid whose ``forbidden`` layer holds
    the forbidden areas and lines.
    """
    x, y, theta = pose.x, pose.y, pose.theta
    if not all(math.isfinite(value) for value in (x, y, theta)):
        return f"the pose ({x}, {y}) heading {theta} is not finite"
    where = f"({x:.2f}, {y:.2f}) heading {math.degrees(theta):.0f}°"
    min_x, min_y, max_x, max_y = bounds
    if not (min_x <= x <= max_x and min_y <= y <= max_y):
        return (f"{where} is off the map (it spans ({min_x:.2f}, {min_y:.2f}) to "
                f"({max_x:.2f}, {max_y:.2f}))")
    if base.robots_gap(pose) < 0.0:
        return f"the robot at {where} would overlap another robot"
    gap = base.body_clearance(pose)
    if gap < 0.0:
        return f"the robot at {where} would overlap a wall or an obstacle (by {-gap:.2f} m)"
    if body_touches(world, world.forbidden, base, pose):
        return f"the robot at {where} would overlap a forbidden area or line"
    return None


def body_touches(grid: MapGrid, layer: np.ndarray, base: RobotBase, pose: Pose2D) -> bool:
    """Whether the body at ``pose`` covers the centre of a cell set in ``layer`` of ``grid``.

    The body is the robot's covering circles (:meth:`cyborg.nav.footprint.Footprint.circles`),
    as the collision check holds them against walls.
    """
    if not layer.any():
        return False
    offsets, radius = base.footprint.circles()
    rows, columns = layer.shape
    for offset in offsets:
        cx = pose.x + float(offset) * math.cos(pose.theta)
        cy = pose.y + float(offset) * math.sin(pose.theta)
        r0, c0 = grid.cell(cx - radius, cy - radius)
        r1, c1 = grid.cell(cx + radius, cy + radius)
        r0, c0, r1, c1 = max(r0, 0), max(c0, 0), min(r1 + 1, rows), min(c1 + 1, columns)
        if r0 >= r1 or c0 >= c1:
            continue
        hit_rows, hit_columns = np.nonzero(layer[r0:r1, c0:c1])
        if len(hit_rows) == 0:
            continue
        centres_x = grid.origin_x + (hit_columns + c0 + 0.5) * grid.resolution
        centres_y = grid.origin_y + (hit_rows + r0 + 0.5) * grid.resolution
        if bool((np.hypot(centres_x - cx, centres_y - cy) <= radius).any()):
            return True
    return False


def limit_command(speed: float, turn_rate: float,
                  drive: DriveLimits | None = None) -> tuple[float, float]:
    """``(speed, turn_rate)`` clamped to the teleoperation limits and the drive's own.

    The limits are :data:`~cyborg.interfaces.robot.TELEOP_MAX_SPEED` and
    :data:`~cyborg.interfaces.robot.TELEOP_MAX_TURN_RATE`, or the drive's maxima where those
    are lower. ValueError for a value that is not finite.
    """
    if not (math.isfinite(speed) and math.isfinite(turn_rate)):
        raise ValueError(f"a speed command must be finite, not ({speed}, {turn_rate})")
    drive = drive or DriveLimits()
    most_speed = min(TELEOP_MAX_SPEED, drive.max_speed)
    most_turn = min(TELEOP_MAX_TURN_RATE, drive.max_turn_rate)
    return (max(-most_speed, min(most_speed, speed)),
            max(-most_turn, min(most_turn, turn_rate)))
