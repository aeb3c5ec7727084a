"""The simulated Pioneer LX base: its differential drive, its body and its bumpers.

The drive has speed and acceleration limits, the body cannot pass through walls nor through
other robots' bodies (:attr:`RobotBase.others`, set by a fleet), and the bumpers report contact.

Motion is unicycle kinematics (forward speed ``v``, turn rate ``w``) integrated exactly over each
step. Commands are followed within the acceleration limits. A step that would make the body
overlap a wall does not happen: the robot stalls, its speed drops to zero, and the bumper on the
side it was moving towards reports contact until the robot moves away again.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numba import njit

from cyborg.nav.footprint import PIONEER_LX, Footprint
from cyborg.nav.geometry import Pose2D
from cyborg.sim.bodies import gap_below, outline_at, outline_bounds


@dataclass(frozen=True)
class DriveLimits:
    """Speed and acceleration limits (MobileSim's pioneer-lx model)."""

    max_speed: float = 2.0  # m/s
    max_turn_rate: float = 3.49  # rad/s
    acceleration: float = 0.5  # m/s^2, speeding up and slowing down
    turn_acceleration: float = 1.74  # rad/s^2


@dataclass
class Bumpers:
    """Contact of the front and rear bumpers."""

    front: bool = False
    rear: bool = False

    @property
    def any(self) -> bool:
        """Whether either bumper reports contact."""
        return self.front or self.rear


@dataclass
class RobotBase:
    """Pose, velocity and contact of the robot in a world given by a clearance grid.

    ``clearance`` holds metres to the nearest wall per cell; cell (0, 0) has its lower-left
    corner at ``origin`` (m), and ``resolution`` is metres per cell. ``speed`` (m/s) and
    ``turn_rate`` (rad/s) are the motion now. ``others`` are other robots' outlines in the map
    (K x 2 corners each, :mod:`cyborg.sim.bodies`): the body keeps clear of them as of walls.
    """

    clearance: np.ndarray  # metres to the nearest wall, per cell of the world grid
    origin: tuple[float, float]
    resolution: float
    pose: Pose2D = field(default_factory=Pose2D)
    footprint: Footprint = PIONEER_LX
    limits: DriveLimits = field(default_factory=DriveLimits)
    speed: float = 0.0
    turn_rate: float = 0.0
    bumpers: Bumpers = field(default_factory=Bumpers)
    odometer: float = 0.0  # metres driven
    bumps: int = 0  # contacts since start
    others: tuple[np.ndarray, ...] = ()  # other robots' outlines, map coordinates

    def __post_init__(self) -> None:
        """The body's outline and the bounding circles of ``others`` (redone as they change)."""
        self._polygon = self.footprint.polygon()
        self._outline: tuple[Pose2D, np.ndarray] | None = None  # see outline
        self._circles = self.footprint.circles()
        # the circle around the outline's corners, about their mean (the body's circle)
        self._reach = float(np.max(np.hypot(*(self._polygon - self._polygon.mean(axis=0)).T)))
        self._span = float(np.max(np.hypot(*self._polygon.T)))  # the body's reach from the pose
        self._far: tuple[float, float, float] | None = None  # see robots_gap
        self._bounds: tuple[tuple[np.ndarray, ...], np.ndarray, np.ndarray, np.ndarray,
                            np.ndarray] = ((), np.zeros((0, 2)), np.zeros(1, np.int64),
                                           np.zeros((0, 2)), np.zeros(0))

    def command(self, speed: float, turn_rate: float, dt: float) -> None:
        """Move for ``dt`` seconds towards the commanded speed and turn rate."""
        limits, pose = self.limits, self.pose
        offsets, radius = self._circles
        self.speed, self.turn_rate, x, y, theta, gap = _drive(
            pose.x, pose.y, pose.theta, self.speed, self.turn_rate, speed, turn_rate,
            limits.max_speed, limits.max_turn_rate, limits.acceleration,
            limits.turn_acceleration, dt, offsets, radius, self.clearance, self.origin[0],
            self.origin[1], self.resolution)
        if self.speed == 0.0 and self.turn_rate == 0.0:  # standing: the body stays put
            if theta != pose.theta:
                self.pose = Pose2D(pose.x, pose.y, theta)
            if self.bumpers.any and self.body_clearance(self.pose) >= self.resolution:
                self.bumpers = Bumpers()
            return
        moved = Pose2D(x, y, theta)
        if self.others:
            gap = min(gap, self.robots_gap(moved, below=gap))
        if gap < 0.0 and gap <= self.body_clearance(pose):  # overlaps, and not backing off
            if not self.bumpers.any:
                self.bumps += 1
            self.bumpers = Bumpers(front=self.speed >= 0, rear=self.speed < 0)
            self.speed = self.turn_rate = 0.0
            return
        self.odometer += math.hypot(moved.x - pose.x, moved.y - pose.y)
        self.pose = moved
        if self.bumpers.any and gap >= self.resolution:
            self.bumpers = Bumpers()  # clear of the wall again (by more than the grid's step)

    def place(self, pose: Pose2D) -> None:
        """Put the robot at ``pose``, standing still."""
        self.pose, self.speed, self.turn_rate, self.bumpers = pose, 0.0, 0.0, Bumpers()

    @property
    def outline(self) -> np.ndarray:
        """The body's outline where it stands: K x 2 map coordinates (kept while it stands).

        The same array until the robot moves: not to be changed by whoever reads it.
        """
        pose = self.pose
        if self._outline is None or self._outline[0] is not pose:
            self._outline = (pose, outline_at(self._polygon, pose))
        return self._outline[1]

    @property
    def span(self) -> float:
        """Metres from the pose to the body's furthest corner."""
        return self._span

    # ------------------------------------------------------------------ contact
    def body_clearance(self, pose: Pose2D) -> float:
        """Smallest gap (metres, negative when overlapping) to a wall or another robot."""
        offsets, radius = self._circles
        walls = float(body_gap(pose.x, pose.y, pose.theta, offsets, radius, self.clearance,
                               self.origin[0], self.origin[1], self.resolution, _NO_POINTS))
        return min(walls, self.robots_gap(pose, below=walls)) if self.others else walls

    def robots_gap(self, pose: Pose2D, below: float = math.inf) -> float:
        """Smallest gap (m, negative when overlapping) to the other robots' outlines.

        The body is at ``pose``; the gap is inf without other robots. Outlines whose bounding
        circle is ``below`` m or further from the body's are not measured: the gap is exact
        when it is less than ``below``, and at least ``below`` otherwise (may be inf).
        """
        if not self.others:
            return math.inf
        known = self._bounds[0]
        if known is not self.others and (len(known) != len(self.others) or any(
                mine is not theirs for mine, theirs in zip(known, self.others, strict=True))):
            starts = np.cumsum([0, *(len(outline) for outline in self.others)])
            corners = np.ascontiguousarray(np.concatenate(self.others), dtype=np.float64)
            self._bounds = (self.others, corners, starts, *outline_bounds(corners, starts))
            self._far = None
        _, corners, starts, middles, radii = self._bounds
        if self._far is None:  # the others' nearest circle, from here: a bound for later poses
            nearest = np.hypot(middles[:, 0] - pose.x, middles[:, 1] - pose.y) - radii
            self._far = (pose.x, pose.y, float(nearest.min()) - self._span)
        x, y, far = self._far
        at_least = far - math.hypot(pose.x - x, pose.y - y)
        if at_least >= below:  # nobody within reach: no need to measure (see the doc)
            return at_least
        return float(gap_below(outline_at(self._polygon, pose), self._reach, corners, starts,
                               middles, radii, below))

    def collides(self, pose: Pose2D) -> bool:
        """Whether the body at ``pose`` overlaps a wall."""
        return self.body_clearance(pose) < 0.0


@njit(cache=True)
def _drive(x: float, y: float, theta: float, speed: float, turn_rate: float,
           wanted_speed: float, wanted_turn: float, max_speed: float, max_turn: float,
           acceleration: float, turn_acceleration: float, dt: float, offsets: np.ndarray,
           radius: float, clearance: np.ndarray, ox: float, oy: float,
           resolution: float) -> tuple[float, float, float, float, float,
                                       float]:  # pragma: no cover - jit
    """One step of the drive: the new speed and turn rate, the pose, its gap to the walls.

    The command is clamped to the limits and followed within the accelerations; standing
    (both zero) the pose is the same (its heading normalised) and the gap not measured (nan).
    """
    wanted_speed = max(-max_speed, min(max_speed, wanted_speed))
    wanted_turn = max(-max_turn, min(max_turn, wanted_turn))
    most = acceleration * dt
    speed += max(-most, min(most, wanted_speed - speed))
    most = turn_acceleration * dt
    turn_rate += max(-most, min(most, wanted_turn - turn_rate))
    if speed == 0.0 and turn_rate == 0.0:
        return speed, turn_rate, x, y, (theta + math.pi) % (2 * math.pi) - math.pi, np.nan
    x, y, theta = arc_step(x, y, theta, speed, turn_rate, dt)
    theta = (theta + math.pi) % (2 * math.pi) - math.pi
    return speed, turn_rate, x, y, theta, body_gap(x, y, theta, offsets, radius, clearance,
                                                    ox, oy, resolution, _NO_POINTS)


_NO_POINTS = np.zeros((0, 2))


@njit(cache=True)
def arc_step(x: float, y: float, theta: float, speed: float, turn_rate: float,
             dt: float) -> tuple[float, float, float]:  # pragma: no cover - jit
    """Where unicycle motion at ``speed`` and ``turn_rate`` for ``dt`` seconds leads.

    The motion is an exact arc (a straight line when not turning); the heading is not
    normalised.
    """
    heading = theta + turn_rate * dt
    if abs(turn_rate) > 1e-9:
        radius = speed / turn_rate
        return (x + radius * (math.sin(heading) - math.sin(theta)),
                y - radius * (math.cos(heading) - math.cos(theta)), heading)
    return x + speed * dt * math.cos(theta), y + speed * dt * math.sin(theta), heading


@njit(cache=True)
def body_gap(x: float, y: float, theta: float, offsets: np.ndarray, radius: float,
             clearance: np.ndarray, ox: float, oy: float, resolution: float,
             points: np.ndarray) -> float:  # pragma: no cover - jit
    """The body's smallest gap (m, negative when overlapping) at a pose.

    Its circles (centres ``offsets`` along the heading, radius ``radius``) are held against a
    clearance grid (looked up by the cell each centre falls in; 0 outside) and against
    ``points`` (N x 2, e.g. laser returns; may be empty).
    """
    rows, columns = clearance.shape
    lowest = np.inf
    for offset in offsets:
        cx = x + offset * math.cos(theta)
        cy = y + offset * math.sin(theta)
        r = int((cy - oy) // resolution)
        c = int((cx - ox) // resolution)
        gap = clearance[r, c] if 0 <= r < rows and 0 <= c < columns else 0.0
        squared = gap * gap  # the nearest point's distance, squared (a root only for it)
        for i in range(points.shape[0]):
            dx, dy = points[i, 0] - cx, points[i, 1] - cy
            if dx * dx + dy * dy < squared:
                squared = dx * dx + dy * dy
        if squared < gap * gap:
            gap = math.sqrt(squared)
        lowest = min(lowest, gap - radius)
    return lowest
