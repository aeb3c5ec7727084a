"""Temporary obstacles: objects seen lately (people), kept out of the planner's way for a while.

The map knows walls; the laser sees what is near; the camera's tracker names what it saw and
where (:data:`cyborg.interfaces.perception.OBJECTS`). :class:`TemporaryObstacles` keeps those
sightings as *discs* on the map: each object a centre and a keep-out radius (its own radius, a
person's 0.3 m by default, plus a margin), refreshed whenever it is seen again and forgotten
``forget_after`` seconds after it was last seen. Times are seconds on whatever clock the caller
uses (simulated time in the simulator); nothing here reads a clock or does I/O::

    obstacles = TemporaryObstacles()
    obstacles.see(7, x=4.0, y=1.5, seen_at=12.0)          # the tracker's object 7
    discs = obstacles.discs(now=13.0)                       # (N, 3): x, y, keep-out radius
    planner.plan(start, goal, discs=discs)

**Moving objects** are placed where they were last seen, carried along their velocity for the
time since then, at most ``extrapolate`` seconds (1 s): a person walking away leaves a disc
just ahead of where they were seen, not one that races down the corridor on a stale estimate.

**Start and goal inside a disc.** A person standing at the goal, or right beside the robot,
must never make the goal unreachable for as long as they stay: :func:`clear_of` shrinks each
disc just enough that given points (the start and the goal) lie outside its lethal zone. The
disc still blocks what it can; the rest is the laser's business (the follower stops before
what it sees).
"""

from __future__ import annotations

import math
from collections.abc import Hashable
from dataclasses import dataclass

import numpy as np

PERSON_RADIUS = 0.3
"""Metres: the radius of the disc a person takes up on the floor (shoulders, a step)."""


@dataclass(frozen=True)
class ObstacleSettings:
    """How seen objects become discs: lengths in metres, times in seconds."""

    object_radius: float = PERSON_RADIUS  # the object's own radius
    margin: float = 0.1  # room kept beyond the object's radius (and the robot's own)
    forget_after: float = 4.0  # seconds after the last sighting that the disc goes
    extrapolate: float = 1.0  # at most this many seconds along the object's velocity

    def __post_init__(self) -> None:
        """Refuses settings that make no discs: every length and time a finite number ≥ 0."""
        for name in ("object_radius", "margin", "forget_after", "extrapolate"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0):
                raise ValueError(f"obstacle setting {name} must be a finite number ≥ 0, "
                                 f"not {value!r}")

    @property
    def keep_out(self) -> float:
        """The disc's radius: the object's radius plus the margin."""
        return self.object_radius + self.margin


@dataclass(frozen=True)
class Sighting:
    """Where an object was last seen (m, map frame), how it moved (m/s), and when (s)."""

    x: float
    y: float
    vx: float
    vy: float
    seen_at: float


class TemporaryObstacles:
    """The objects seen lately, by key (the tracker's id), each until it is forgotten.

    ``settings`` default to :class:`ObstacleSettings`. Not thread-safe: the simulator holds
    its lock around every call.
    """

    def __init__(self, settings: ObstacleSettings | None = None) -> None:
        self.settings = settings or ObstacleSettings()
        self._seen: dict[Hashable, Sighting] = {}

    def __len__(self) -> int:
        """How many objects are held (forgotten ones go at :meth:`forget` or :meth:`discs`)."""
        return len(self._seen)

    def see(self, key: Hashable, x: float, y: float, seen_at: float,
            velocity: tuple[float, float] = (0.0, 0.0)) -> bool:
        """Take a sighting of object ``key``; whether it was taken.

        A sighting older than the one held for ``key`` changes nothing (messages may arrive out
        of order); one with a coordinate or time that is not finite is refused (False). A
        velocity that is not finite counts as standing still.
        """
        if not all(math.isfinite(value) for value in (x, y, seen_at)):
            return False
        held = self._seen.get(key)
        if held is not None and held.seen_at > seen_at:
            return False
        vx, vy = velocity
        if not (math.isfinite(vx) and math.isfinite(vy)):
            vx = vy = 0.0
        self._seen[key] = Sighting(x, y, vx, vy, seen_at)
        return True

    def forget(self, now: float) -> int:
        """Drop the objects unseen for longer than ``forget_after``; how many went."""
        limit = now - self.settings.forget_after
        gone = [key for key, sighting in self._seen.items() if sighting.seen_at < limit]
        for key in gone:
            del self._seen[key]
        return len(gone)

    def clear(self) -> None:
        """Forget every object at once (a new map, a teleported robot)."""
        self._seen.clear()

    def discs(self, now: float, near: tuple[float, float] | None = None,
              within: float = math.inf) -> np.ndarray:
        """The discs as of ``now``: an (N, 3) array of centre x, y and keep-out radius.

        Forgets what is due first. Each centre is the object's last position carried along its
        velocity for the time since (at most ``extrapolate`` s). With ``near``, only discs whose
        centre lies within ``within`` metres of that point.
        """
        self.forget(now)
        settings = self.settings
        rows = []
        for sighting in self._seen.values():
            ahead = min(max(now - sighting.seen_at, 0.0), settings.extrapolate)
            x, y = sighting.x + sighting.vx * ahead, sighting.y + sighting.vy * ahead
            if near is not None and math.hypot(x - near[0], y - near[1]) > within:
                continue
            rows.append((x, y, settings.keep_out))
        return np.array(rows, np.float64).reshape(-1, 3)


def clear_of(discs: np.ndarray, points: list[tuple[float, float]], lethal: float,
             spare: float) -> np.ndarray:
    """``discs`` shrunk so that each of ``points`` lies outside every disc's lethal zone.

    The lethal zone of a disc is its keep-out radius plus ``lethal`` (the robot's own radius
    that the planner inflates by); a point closer than that to a centre shrinks the disc's
    radius until the point is ``spare`` metres outside the zone. Radii may go below zero: then
    the zone is smaller than ``lethal`` around the centre, or gone. The discs are copied.
    """
    shrunk = np.array(discs, np.float64).reshape(-1, 3)
    for x, y in points:
        distance = np.hypot(shrunk[:, 0] - x, shrunk[:, 1] - y)
        np.minimum(shrunk[:, 2], distance - lethal - spare, out=shrunk[:, 2])
    return shrunk


def path_blocked(discs: np.ndarray, points: np.ndarray, lethal: float,
                 hysteresis: float) -> bool:
    """Whether a path's sampled ``points`` (M, 2) come into a disc's lethal zone.

    A point counts only when deeper than ``hysteresis`` metres into the zone, so a path planned
    around a disc is not found blocked again when the object's position shakes a little.
    """
    if len(discs) == 0 or len(points) == 0:
        return False
    gaps = np.hypot(points[:, None, 0] - discs[None, :, 0], points[:, None, 1] - discs[None, :, 1])
    return bool((gaps < discs[None, :, 2] + lethal - hysteresis).any())
