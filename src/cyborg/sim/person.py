"""One simulated person: how people walk (settings), who walks where (plan), and their state.

:class:`~cyborg.sim.people.Crowd` walks them; see :mod:`cyborg.sim.people` for how.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import Enum

import numpy as np

from cyborg.nav.geometry import Pose2D
from cyborg.sim.people_routes import Point


@dataclass(frozen=True)
class PeopleSettings:
    """How people walk: body (m), speeds (m/s), pauses and patience (s), look-ahead (m)."""

    radius: float = 0.25  # metres: a person's body, seen from above
    height: float = 1.7  # metres: what the camera's box spans
    min_speed: float = 0.5
    max_speed: float = 1.5
    min_pause: float = 2.0
    max_pause: float = 8.0
    look_ahead: float = 0.6  # metres of free way a walking person wants beyond the bodies
    patience: float = 3.0  # seconds blocked before turning back


@dataclass(frozen=True)
class PersonPlan:
    """Who walks where: a name, a start point and waypoints (m); ``line`` of the map, if any."""

    name: str
    start: Point
    waypoints: tuple[Point, ...]
    line: int = 0


class Gait(Enum):
    """What a person is doing now."""

    WALKING = "walking"
    PAUSING = "pausing"  # at a waypoint, for a while
    WAITING = "waiting"  # blocked on the way
    STANDING = "standing"  # no waypoint can be reached: stays where they are


@dataclass
class Person:
    """One person: where they are and head (m, rad), how fast they walk, where they go next.

    ``leg_from`` is the point they last left (a waypoint, their start, or where they turned
    back), ``goal`` the point they walk to now, ``then`` the index of the waypoint they set off
    for after the next pause; ``route`` the rest of the way to ``goal`` ((K, 2), m), ``trail``
    the corners they passed on it (the way back).
    """

    name: str
    x: float
    y: float
    speed: float
    waypoints: tuple[Point, ...]
    heading: float = 0.0
    gait: Gait = Gait.WALKING
    leg_from: Point = (0.0, 0.0)
    goal: Point = (0.0, 0.0)
    then: int = 0
    returning: bool = False  # turned back, to the point they left
    route: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    trail: list[Point] = field(default_factory=list)
    until: float = 0.0  # when a pause ends, simulated seconds
    waited: float = 0.0  # seconds blocked so far
    pocket: tuple[float, float] | None = None  # where no step off a robot's way was free
    refuge: np.ndarray | None = None  # the walk to a place off a waiting robot's way, (K, 2)

    @property
    def pose(self) -> Pose2D:
        """Where the person stands, facing where they walk."""
        return Pose2D(self.x, self.y, self.heading)
