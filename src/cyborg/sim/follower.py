"""Following a planned path: a carrot along the path, slowing near obstacles and at the goal.

The robot steers towards a point ``lookahead`` metres further along the path than the point of
the path nearest to it — a carrot on the polyline, so corners are rounded by at most the
lookahead and never cut through walls the planner kept clear of. It turns in place when the
carrot is far off its heading, slows where the laser sees obstacles close ahead, and brakes in
time for sharp corners (down to a speed at which it can take them) and for the goal. On
arrival it turns to the goal's heading if asked.

Progress is measured *along the path* (the distance still to go), never as straight-line
distance: a path may first lead away from a goal.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from cyborg.nav.geometry import Path, Pose2D, normalize_angle


@dataclass(frozen=True)
class FollowerSettings:
    """Speeds in m/s and rad/s, distances in metres (ARNL's names in brackets)."""

    cruise_speed: float = 1.0  # [FastSpeed]
    slow_speed: float = 0.25  # [SlowSpeed], near obstacles
    turn_rate: float = 1.5
    lookahead: float = 0.5
    goal_tolerance: float = 0.15  # [GoalDistanceTol]
    heading_tolerance: float = math.radians(3)  # [GoalAngleTol]
    turn_in_place: float = math.radians(50)  # heading error above which the robot turns first
    stop_distance: float = 0.45  # obstacle range ahead (from the scanner) where it stops
    slow_distance: float = 1.5  # obstacle range ahead below which it slows down
    deceleration: float = 0.5  # m/s^2 the robot can brake with
    sharp_corner: float = math.radians(30)  # turns of the path above this are taken slower


@dataclass(frozen=True)
class Command:
    """A speed command: ``speed`` in m/s, ``turn_rate`` in rad/s, and what the follower saw.

    ``arrived``: the goal (and its heading, if asked for) is reached; ``remaining``: metres
    still to go along the path.
    """

    speed: float
    turn_rate: float
    arrived: bool = False
    blocked: bool = False  # an obstacle stands in the way
    remaining: float = math.inf


class PathFollower:
    """Turns a path, the robot's pose and a laser scan into speed commands.

    With ``use_heading`` the robot turns to the path's final heading on arrival; ``settings``
    default to :class:`FollowerSettings`.
    """

    def __init__(self, path: Path, use_heading: bool,
                 settings: FollowerSettings | None = None) -> None:
        self.path, self.use_heading = path, use_heading
        self.settings = settings or FollowerSettings()
        self._at_goal = False
        self._corners, self._corner_speeds = self._sharp_corners()

    def update(self, pose: Pose2D, front_range: float,
               stop_range: float | None = None) -> Command:
        """The command for the robot at ``pose`` now.

        ``front_range``: metres to the nearest obstacle ahead of the scanner in a corridor a
        little wider than the robot (to slow down); ``stop_range``: the same in a corridor
        exactly as wide as the robot (to stop; default ``front_range``). A door jamb beside the
        path slows the robot but does not stop it.
        """
        s = self.settings
        along, _gap = self.path.project(pose.x, pose.y)
        remaining = self.path.length - along
        to_goal = math.hypot(self.path.points[-1, 0] - pose.x, self.path.points[-1, 1] - pose.y)
        if self._at_goal or (remaining <= s.goal_tolerance and to_goal <= s.goal_tolerance):
            self._at_goal = True
            return self._final_turn(pose)
        carrot = self.path.point_at(along + s.lookahead)
        if math.hypot(carrot[0] - pose.x, carrot[1] - pose.y) < 1e-6:
            carrot = (float(self.path.points[-1, 0]), float(self.path.points[-1, 1]))
        error = normalize_angle(math.atan2(carrot[1] - pose.y, carrot[0] - pose.x) - pose.theta)
        turn = max(-s.turn_rate, min(s.turn_rate, 2.0 * error))
        if abs(error) > s.turn_in_place:
            return Command(0.0, turn, remaining=remaining)
        speed = s.cruise_speed * math.cos(error)
        speed = min(speed, math.sqrt(2 * s.deceleration * max(to_goal - 0.05, 0.0)) + 0.05,
                    self._corner_limit(along))
        stop = front_range if stop_range is None else stop_range
        blocked = stop <= s.stop_distance and stop + 0.05 < to_goal
        if blocked:
            speed = 0.0
        elif front_range < s.slow_distance:
            share = max(0.0, front_range - s.stop_distance) / (s.slow_distance - s.stop_distance)
            speed = min(speed, s.slow_speed + share * (s.cruise_speed - s.slow_speed))
        return Command(max(speed, 0.0), turn, blocked=blocked, remaining=remaining)

    def _sharp_corners(self) -> tuple[np.ndarray, np.ndarray]:
        """Where along the path it turns by more than ``sharp_corner``, and each corner's speed.

        A corner's speed is the cruise speed times the cosine of the turn, at least the slow
        speed.
        """
        s, points = self.settings, self.path.points
        if len(points) < 3:
            return np.zeros(0), np.zeros(0)
        steps = np.diff(points, axis=0)
        lengths = np.hypot(steps[:, 0], steps[:, 1])
        headings = np.arctan2(steps[:, 1], steps[:, 0])
        turns = np.abs((np.diff(headings) + np.pi) % (2 * np.pi) - np.pi)
        along = np.cumsum(lengths)[:-1]  # distance to each inner vertex
        sharp = (turns > s.sharp_corner) & (lengths[:-1] > 1e-9) & (lengths[1:] > 1e-9)
        speeds = np.maximum(s.cruise_speed * np.cos(np.minimum(turns[sharp], np.pi / 2)),
                            s.slow_speed)
        return along[sharp], speeds

    def _corner_limit(self, along: float) -> float:
        """The highest speed from which the robot can still slow down for every sharp corner.

        That is, down to each corner's speed before reaching it; corners the robot is already at
        count from here.
        """
        limit = math.inf
        s = self.settings
        for at, speed in zip(self._corners, self._corner_speeds, strict=True):
            ahead = max(float(at) - along - s.lookahead, 0.0)
            if at + s.lookahead < along:
                continue  # behind the robot
            limit = min(limit, math.sqrt(float(speed) ** 2 + 2 * s.deceleration * ahead))
        return limit

    def _final_turn(self, pose: Pose2D) -> Command:
        s = self.settings
        if not self.use_heading or self.path.final_heading is None:
            return Command(0.0, 0.0, arrived=True, remaining=0.0)
        error = normalize_angle(self.path.final_heading - pose.theta)
        if abs(error) <= s.heading_tolerance:
            return Command(0.0, 0.0, arrived=True, remaining=0.0)
        turn = max(-s.turn_rate, min(s.turn_rate, 2.0 * error))
        if abs(turn) < 0.15:
            turn = math.copysign(0.15, error)
        return Command(0.0, turn, remaining=0.0)


SLOW_CORRIDOR = 0.3
"""Half width (m) of the corridor ahead in which obstacles slow the robot: a little wider than
the LX; it stops only for obstacles within its own half width."""


def front_ranges(ranges: np.ndarray, angles: np.ndarray, half_widths: tuple[float, ...],
                 range_max: float = 30.0) -> tuple[float, ...]:
    """Distance ahead (m) to the nearest return within corridors of the given half widths.

    One projection of the scan serves all of them; inf where a corridor is clear. Returns
    beyond ``range_max`` count as nothing seen.
    """
    found = _nearest_ahead(np.ascontiguousarray(ranges, dtype=np.float64),
                           np.ascontiguousarray(angles, dtype=np.float64),
                           np.array(half_widths, dtype=np.float64), range_max)
    return tuple(float(value) for value in found)


@njit(cache=True)
def _nearest_ahead(ranges: np.ndarray, angles: np.ndarray, half_widths: np.ndarray,
                   range_max: float) -> np.ndarray:  # pragma: no cover - jit
    """:func:`front_ranges` on arrays: the nearest return ahead within each half width."""
    found = np.full(half_widths.shape[0], np.inf)
    for beam in range(ranges.shape[0]):
        if not ranges[beam] <= range_max or abs(angles[beam]) >= math.pi / 2:
            continue
        along = ranges[beam] * math.cos(angles[beam])
        side = abs(ranges[beam] * math.sin(angles[beam]))
        for corridor in range(half_widths.shape[0]):
            if side <= half_widths[corridor] and along < found[corridor]:
                found[corridor] = along
    return found



@njit(cache=True)
def ahead_of_the_map(ranges: np.ndarray, angles: np.ndarray, x: float, y: float, theta: float,
                     clearance: np.ndarray, origin_x: float, origin_y: float, resolution: float,
                     mapped: float, slow_width: float, stop_width: float,
                     range_max: float = 30.0) -> tuple[float, float]:  # pragma: no cover - jit
    """:func:`front_ranges` for two corridors, the second blind to the map's walls.

    The scanner stands at ``(x, y)`` facing ``theta``; a return whose point lies in a cell of
    the ``clearance`` grid (metres to the map's walls; points off it count as its edge) less
    than ``mapped`` m from a wall is not seen in the ``stop_width`` corridor.
    """
    rows, columns = clearance.shape
    slow, stop = np.inf, np.inf
    for beam in range(ranges.shape[0]):
        if not ranges[beam] <= range_max or abs(angles[beam]) >= math.pi / 2:
            continue
        along = ranges[beam] * math.cos(angles[beam])
        side = abs(ranges[beam] * math.sin(angles[beam]))
        if side <= slow_width and along < slow:
            slow = along
        if side <= stop_width and along < stop:
            px = x + ranges[beam] * math.cos(theta + angles[beam])
            py = y + ranges[beam] * math.sin(theta + angles[beam])
            r = min(max(math.floor((py - origin_y) / resolution), 0), rows - 1)
            c = min(max(math.floor((px - origin_x) / resolution), 0), columns - 1)
            if clearance[r, c] > mapped:
                stop = along
    return slow, stop


@njit(cache=True)
def any_within(points: np.ndarray, others: np.ndarray,
               limit: float) -> bool:  # pragma: no cover - jit
    """Whether a point of ``points`` lies closer than ``limit`` to one of ``others``.

    Points outside the box around ``others`` grown by ``limit`` are passed over at once: of a
    scan's returns, only the few near the path ahead are measured against it.
    """
    low_x, high_x = others[:, 0].min() - limit, others[:, 0].max() + limit
    low_y, high_y = others[:, 1].min() - limit, others[:, 1].max() + limit
    squared = limit * limit
    for i in range(points.shape[0]):
        px, py = points[i, 0], points[i, 1]
        if px < low_x or px > high_x or py < low_y or py > high_y:
            continue
        for j in range(others.shape[0]):
            if (px - others[j, 0]) ** 2 + (py - others[j, 1]) ** 2 < squared:
                return True
    return False
