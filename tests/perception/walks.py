"""Scripted people in front of the simulated camera, for tests of the tracker's identities.

A :class:`Walk` is where one person is at each moment: straight legs between waypoints at
their own speeds, with pauses. :func:`watch` films walks with the simulator's camera
(:class:`~cyborg.sim.camera.SimCamera`: its field of view, depth and bearing noise, misses, and
occlusion by walls and by the people themselves) from a robot standing still, sends each frame
the way the robot's tracker takes it (the camera node's ``Predictions`` message, screened,
placed on the map, tracked) and says which track ids each true person was given::

    ids = watch([Walk((3, -2), (3, 2), speed=1.2)], seconds=10, seed=1)
    ids.per_person == [1]        # one track id for the one person

A track is credited to the true person nearest to it, within :data:`CREDIT` metres, in each
frame it is seen in.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from cyborg.bus.msgs.builtin_interfaces.msg import Time
from cyborg.bus.msgs.std_msgs.msg import Header
from cyborg.interfaces.detection_messages import predictions_message
from cyborg.perception import RobotPose, Tracker, locate, screen
from cyborg.perception.tracker import TrackerSettings
from cyborg.sim.camera import SimCamera
from cyborg.sim.sights import Sights

RESOLUTION = 0.05
"""Metres per cell of the test world's wall grid."""
WORLD = (-2.0, -12.0, 30.0, 12.0)
"""The test world's extent (x0, y0, x1, y1), metres; the robot stands at (0, 0) facing +x."""
CREDIT = 1.5
"""Metres: a track is credited to the nearest true person within this distance."""
PERSON_RADIUS, PERSON_HEIGHT = 0.25, 1.7


@dataclass(frozen=True)
class Walk:
    """One person's walk: waypoints (m) walked in turn at ``speed`` m/s, pausing ``pause`` s
    at each waypoint after the first; before ``start`` s they stand at the first."""

    points: tuple[tuple[float, float], ...]
    speed: float = 1.2
    pause: float = 0.0
    start: float = 0.0

    def __init__(self, *points: tuple[float, float], speed: float = 1.2, pause: float = 0.0,
                 start: float = 0.0) -> None:
        object.__setattr__(self, "points", tuple(points))
        object.__setattr__(self, "speed", speed)
        object.__setattr__(self, "pause", pause)
        object.__setattr__(self, "start", start)

    def at(self, time: float) -> tuple[float, float]:
        """Where the person is ``time`` seconds into the walk (at the last point once done)."""
        left = time - self.start
        here = self.points[0]
        for there in self.points[1:]:
            if left <= 0:
                return here
            leg = math.dist(here, there) / self.speed
            if left < leg:
                share = left / leg
                return (here[0] + share * (there[0] - here[0]),
                        here[1] + share * (there[1] - here[1]))
            left -= leg + self.pause
            here = there
        return here


@dataclass
class Identities:
    """The track ids each true person was given (by the walks' order)."""

    ids: list[set[int]]
    frames: int = 0
    seen: list[int] = field(default_factory=list)
    """Frames in which each person's track was seen."""

    @property
    def per_person(self) -> list[int]:
        """How many distinct track ids each person had."""
        return [len(ids) for ids in self.ids]


def wall_grid(*boxes: tuple[float, float, float, float]) -> np.ndarray:
    """The world's wall grid (rows along y), with each box (x0, y0, x1, y1, metres) filled."""
    x0, y0, x1, y1 = WORLD
    grid = np.zeros((round((y1 - y0) / RESOLUTION), round((x1 - x0) / RESOLUTION)), bool)
    for bx0, by0, bx1, by1 in boxes:
        grid[round((by0 - y0) / RESOLUTION):round((by1 - y0) / RESOLUTION),
             round((bx0 - x0) / RESOLUTION):round((bx1 - x0) / RESOLUTION)] = True
    return grid


def watch(walks: list[Walk], seconds: float, seed: int,
          boxes: tuple[tuple[float, float, float, float], ...] = (),
          settings: TrackerSettings | None = None,
          heading: Callable[[float], float] = lambda _time: 0.0) -> Identities:
    """Film ``walks`` for ``seconds`` among walls ``boxes``; the ids the tracker gave each.

    The robot stands at (0, 0), turned to ``heading(time)`` radians (default: facing +x).
    """
    camera = SimCamera(wall_grid(*boxes), (WORLD[0], WORLD[1]), RESOLUTION, seed=seed)
    tracker = Tracker(settings)
    result = Identities([set() for _ in walks], seen=[0] * len(walks))
    for frame in range(round(seconds * camera.spec.rate)):
        now = frame / camera.spec.rate
        pose = RobotPose(0.0, 0.0, heading(now))
        truth = np.array([walk.at(now) for walk in walks])
        sights = Sights(("person",) * len(walks), truth, np.full(len(walks), PERSON_RADIUS),
                        np.full(len(walks), PERSON_HEIGHT))
        seen = camera.observe(pose.x, pose.y, pose.theta, sights)
        stamp_ns = round(now * 1e9)
        header = Header(stamp=Time(sec=stamp_ns // 1_000_000_000,
                                   nanosec=stamp_ns % 1_000_000_000), frame_id="camera")
        message = predictions_message(seen, header, stamp_ns)
        detections, _rejected = screen(message.predictions)
        tracker.update(now, locate(detections, pose))
        for item in tracker.objects():
            if item.last_seen != now:
                continue
            gaps = np.hypot(truth[:, 0] - item.x, truth[:, 1] - item.y)
            person = int(np.argmin(gaps))
            if gaps[person] <= CREDIT:
                result.ids[person].add(item.id)
                result.seen[person] += 1
        result.frames += 1
    return result
