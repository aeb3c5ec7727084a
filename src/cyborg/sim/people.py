"""People walking in the simulated world: between waypoints, pausing, keeping out of the way.

A :class:`Crowd` walks its :class:`Person` s over the map's free space. Each person has a
walking speed of their own (drawn between :attr:`PeopleSettings.min_speed` and
:attr:`~PeopleSettings.max_speed`, 0.5 to 1.5 m/s), a list of waypoints they visit in turn and
then again from the first, and pauses of random length (:attr:`~PeopleSettings.min_pause` to
:attr:`~PeopleSettings.max_pause` s) at each. Between two waypoints they follow the route the
navigation planner (:class:`cyborg.nav.planner.Planner`) finds on the map, which keeps the
robot's clearance from walls and forbidden zones, so nobody ever walks into a wall; routes are
planned once per pair of points and reused (:mod:`cyborg.sim.people_routes`).

Nobody walks into anybody: a person whose way ahead (:attr:`~PeopleSettings.look_ahead` m
plus both bodies) is taken by a robot or another person stops and waits. Still blocked after
:attr:`~PeopleSettings.patience` s, they turn back towards the waypoint they came from, as a
person in a corridor does when a robot stands in it. Someone standing at their waypoint makes
it reached (within :data:`ARRIVED_NEAR`). And people make room for robots: whoever is closer
than :data:`ROOM` to a robot's body steps away from it, if walls and others let them.

A person's body is a circle of :attr:`~PeopleSettings.radius` m, drawn as a regular octagon
around it (:meth:`Crowd.outlines`): the shape the laser sees and the robot's drive cannot enter,
exactly as another robot's outline (:mod:`cyborg.sim.bodies`). The crowd steps every
:data:`WALK_PERIOD` (5 Hz), which at 1.5 m/s is 30 cm a step::

    crowd = Crowd(planner, random_people(arnl_map, planner, 3, seed=1), seed=1)
    crowd.advance(0.1, robot_outlines)
    crowd.positions          # (N, 2) metres in the map frame
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import NamedTuple

import numpy as np

from cyborg.nav.planner import Planner
from cyborg.sim.bodies import outline_points
from cyborg.sim.crowd_geometry import in_robots_way, in_the_way, line_clear
from cyborg.sim.people_routes import Point, RouteBook
from cyborg.sim.person import Gait, PeopleSettings, Person, PersonPlan

NEAR = 3.0
"""Metres from a robot within which people are bodies its drive cannot enter, and points its
navigator keeps clear of even behind it (further off, only its laser sees them)."""


class Meeting(NamedTuple):
    """What one robot meets of a crowd: bodies near it, points along them, circles further off.

    ``bodies`` are the octagons (8 x 2 each, m) of the people within :data:`NEAR`, ``points``
    (N x 2) lie along them, and ``circles`` ((M, 3): x, y, radius) are everybody else within
    the laser's reach. (An octagon holds its person's circle: a beam reaches the octagon
    first, so the laser that sees the bodies needs no circles of the same people.)
    """

    bodies: tuple[np.ndarray, ...]
    points: np.ndarray
    circles: np.ndarray


NOBODY = Meeting((), np.zeros((0, 2)), np.zeros((0, 3)))
"""What a robot meets where no one walks."""
ROOM = 0.3
"""Metres people keep between their bodies and a robot's when they can: closer, they step
away from it (the robot's body counted as the circle around its outline)."""
SIDESTEPS = (0.0, math.pi / 4, -math.pi / 4, math.pi / 2, -math.pi / 2)
"""Turns (rad) from straight away from a robot that a person making room for it tries."""
WALK_PERIOD = 0.2
"""Seconds between two steps of the crowd: 30 cm at 1.5 m/s, fine enough for walking people
and half the work of stepping them with the robots' 10 Hz sensors."""
AHEAD = 2.5
"""Metres ahead of a robot within which people step out of its way."""
ARRIVED_NEAR = 1.5
"""Metres from a waypoint within which a person blocked on the way counts as arrived there:
someone else stands on it (a robot, a person pausing)."""
OCTAGON = np.array([[math.cos(k * math.pi / 4), math.sin(k * math.pi / 4)] for k in range(8)])
"""A regular octagon of circumradius 1, counter-clockwise."""


class Crowd:
    """People walking on a map; see the module doc. ``seed`` makes their speeds and pauses."""

    def __init__(self, planner: Planner, plans: Sequence[PersonPlan],
                 settings: PeopleSettings | None = None, seed: int = 0) -> None:
        self.settings = settings or PeopleSettings()
        self.routes = RouteBook(planner)
        self._random = np.random.default_rng(seed)
        self.time = 0.0
        s = self.settings
        self.people = [Person(plan.name, plan.start[0], plan.start[1],
                              float(self._random.uniform(s.min_speed, s.max_speed)),
                              plan.waypoints, leg_from=plan.start) for plan in plans]
        self._clearance = planner.wall_clearance
        for person in self.people:
            self._leave(person)
        # the octagon's edges touch the circle of `radius`, so the body is at least that round
        self._octagon = OCTAGON * (s.radius / math.cos(math.pi / 8))
        self._samples = outline_points(self._octagon, 0.1)  # around a body, from its centre
        self._owed = 0.0  # seconds not walked yet (see :meth:`due`)

    def __len__(self) -> int:
        """How many people walk."""
        return len(self.people)

    @property
    def positions(self) -> np.ndarray:
        """Every person's position, (N, 2) metres in the map frame."""
        return np.array([(p.x, p.y) for p in self.people], dtype=np.float64).reshape(-1, 2)

    def outlines(self) -> np.ndarray:
        """Every person's body as an octagon: (N, 8, 2) map coordinates."""
        return self.positions[:, None, :] + self._octagon[None, :, :]

    def circles(self) -> np.ndarray:
        """Every person's body as a circle: (N, 3) rows of x, y, radius (m)."""
        return np.column_stack([self.positions, np.full(len(self.people), self.settings.radius)])

    def meeting(self, x: float, y: float, reach: float) -> Meeting:
        """What a robot at ``(x, y)`` meets of the crowd (see :class:`Meeting`)."""
        if not self.people:
            return NOBODY
        positions = self.positions
        distance = np.hypot(positions[:, 0] - x, positions[:, 1] - y)
        seen = positions[(distance <= reach) & (distance > NEAR)]
        circles = np.empty((len(seen), 3))
        circles[:, :2], circles[:, 2] = seen, self.settings.radius
        close = np.flatnonzero(distance <= NEAR)
        if len(close) == 0:
            return Meeting((), NOBODY.points, circles)
        near = tuple(positions[index] + self._octagon for index in close)
        points = (positions[close, None, :] + self._samples[None, :, :]).reshape(-1, 2)
        return Meeting(near, points, circles)

    def beside(self, planner: Planner, outline: np.ndarray, dt: float, reach: float) -> Meeting:
        """Walk ``dt`` s around one robot and say what it meets.

        ``outline`` is K x 2, its first and last corners the front edge's, as
        :meth:`~cyborg.nav.footprint.Footprint.polygon` gives them.

        A robot whose ``planner`` is not the crowd's has switched maps: it meets nobody, and
        nobody walks.
        """
        if planner is not self.routes.planner:
            return NOBODY
        middle = outline.sum(axis=0) / len(outline)
        walked = self.due(dt)
        if walked:
            front = (outline[0] + outline[-1]) / 2 - middle  # the middle of the front edge
            self.advance(walked, [outline], [math.atan2(front[1], front[0])])
        return self.meeting(float(middle[0]), float(middle[1]), reach)

    def due(self, dt: float) -> float:
        """Count ``dt`` s more; the seconds to walk now (0 until :data:`WALK_PERIOD` is due).

        People walk in steps of :data:`WALK_PERIOD`, whatever the robots' sensor period.
        """
        self._owed += dt
        if self._owed < WALK_PERIOD - 1e-9:
            return 0.0
        walked, self._owed = self._owed, 0.0
        return walked

    # ------------------------------------------------------------------ walking
    def advance(self, dt: float, robots: Sequence[np.ndarray] = (),
                headings: Sequence[float] = ()) -> None:
        """Walk everyone ``dt`` seconds, keeping clear of ``robots`` (outlines, K x 2 each).

        With the robots' ``headings`` (rad), people out of their way ahead too.
        """
        self.time += dt
        walking = []
        for person in self.people:
            if person.gait is Gait.STANDING:
                continue
            if person.gait is Gait.PAUSING and (
                    self.time < person.until
                    or not self._leave(person)):
                continue
            if len(person.route) == 0:
                self._arrive(person)
                continue
            ahead = person.route[0]
            if (ahead[0], ahead[1]) != (person.x, person.y):
                person.heading = math.atan2(ahead[1] - person.y, ahead[0] - person.x)
            walking.append(person)
        circles = np.empty((len(robots), 3))
        for index, outline in enumerate(robots):
            middle = outline.sum(axis=0) / len(outline)
            circles[index, :2] = middle
            circles[index, 2] = math.sqrt(float(np.max(np.sum((outline - middle) ** 2, axis=1))))
        if walking:
            for person, blocked in zip(walking, self._blocked(walking, circles), strict=True):
                self._walk(person, dt, bool(blocked))
        if len(circles):
            self._make_room(dt, circles, headings)

    def _make_room(self, dt: float, robots: np.ndarray, headings: Sequence[float]) -> None:
        """People step out of robots' way, where walls and other people let them.

        Whoever is closer than :data:`ROOM` to a robot's body steps away from it; whoever is
        ahead of it (within :data:`AHEAD` along its heading, and its body and ours and
        :data:`ROOM` aside) steps aside, else further ahead. A robot stuck beside a person
        would be stuck for good.
        """
        s = self.settings
        for index, (cx, cy, radius) in enumerate(robots):
            need = radius + s.radius + ROOM
            touched = in_robots_way(self.positions,  # as the robots before this one left them
                                    cx, cy, need,
                                    headings[index] if index < len(headings) else math.nan,
                                    AHEAD)
            for person in (self.people[k] for k in np.flatnonzero(touched)):
                self._room_for(person, cx, cy, need,
                               headings[index] if index < len(headings) else None, dt)

    def _room_for(self, person: Person, cx: float, cy: float, need: float,
                  heading: float | None, dt: float) -> None:
        """``person`` steps out of the way of a robot at ``(cx, cy)`` heading ``heading``.

        ``need`` is the gap (m, centre to centre) the person keeps from the robot.
        """
        dx, dy = person.x - cx, person.y - cy
        distance = math.hypot(dx, dy)
        if heading is not None:
            ux, uy = math.cos(heading), math.sin(heading)
            along, across = dx * ux + dy * uy, uy * dx - ux * dy
            if 0.0 < along <= AHEAD and abs(across) < need:
                side = heading + (-math.pi / 2 if across >= 0 else math.pi / 2)
                self._step_away(person, side, person.speed * dt, (0.0, math.pi / 4, math.pi / 2))
                return
        if distance >= need:
            return
        if distance < 1e-9:
            dx, dy, distance = -math.cos(person.heading), -math.sin(person.heading), 1.0
        self._step_away(person, math.atan2(dy, dx), min(need - distance, person.speed * dt),
                        SIDESTEPS)

    def _step_away(self, person: Person, away: float, step: float,
                   turns: tuple[float, ...]) -> None:
        """Step ``step`` m towards ``away`` (rad), or the first of ``turns`` from it that is free.

        Each turn is tried to the left and then to the right.
        """
        for turn in turns:
            for sign in ((1.0, -1.0) if turn else (1.0,)):
                to = (person.x + step * math.cos(away + sign * turn),
                      person.y + step * math.sin(away + sign * turn))
                if self._free(person, to):
                    here = (person.x, person.y)
                    person.trail.append(here)  # the way back passes here
                    if len(person.route) and not self._clear(to, person.route[0]):
                        person.route = np.vstack([here, person.route])  # and the way on
                    person.x, person.y = to
                    return

    def _free(self, person: Person, to: Point) -> bool:
        """Whether ``person`` may step to ``to``: clear of walls and other people."""
        s = self.settings
        if not self._clear((person.x, person.y), np.array(to)):
            return False
        return not any(other is not person and math.hypot(other.x - to[0], other.y - to[1])
                       < 2 * s.radius for other in self.people)

    def _walk(self, person: Person, dt: float, blocked: bool) -> None:
        if blocked:
            if math.hypot(person.goal[0] - person.x, person.goal[1] - person.y) <= ARRIVED_NEAR:
                self._arrive(person)  # someone stands at the waypoint: near enough
                return
            person.gait = Gait.WAITING
            person.waited += dt
            if person.waited >= self.settings.patience:
                self._turn_back(person)
            return
        person.gait, person.waited = Gait.WALKING, 0.0
        left = person.speed * dt
        while left > 0.0 and len(person.route):
            tx, ty = person.route[0]
            gap = math.hypot(tx - person.x, ty - person.y)
            if gap <= left:
                person.x, person.y = float(tx), float(ty)
                person.trail.append((person.x, person.y))
                person.route = person.route[1:]
                left -= gap
            else:
                person.x += (tx - person.x) * left / gap
                person.y += (ty - person.y) * left / gap
                left = 0.0
        if len(person.route) == 0:
            self._arrive(person)

    def _blocked(self, walking: list[Person], robots: np.ndarray) -> np.ndarray:
        """For each of ``walking``: whether a robot or another person stands in the way ahead.

        ``robots`` are (M, 3): x, y, radius. In the way means ahead of them (along their
        heading) by at most both bodies and :attr:`~PeopleSettings.look_ahead`, and less than
        both bodies (and 10 cm) aside.
        """
        s = self.settings
        here = np.array([(p.x, p.y, p.heading) for p in walking])
        return in_the_way(here, self.positions, s.radius, robots, s.look_ahead)

    def _arrive(self, person: Person) -> None:
        """Pause at the waypoint (or as near it as they got), then go on to the next."""
        s = self.settings
        person.gait = Gait.PAUSING
        person.leg_from = person.goal
        person.trail = person.trail[-1:] if len(person.route) == 0 else []
        person.until = self.time + float(self._random.uniform(s.min_pause, s.max_pause))

    def _leave(self, person: Person) -> bool:
        """Set off for waypoint ``then``, or the next one that can be reached; whether any.

        The leg is the route between the two points (planned once,
        :class:`~cyborg.sim.people_routes.RouteBook`), joined from where the person stands:
        straight to its second corner when nothing is in the way, else back along what is left
        of the way they came.
        """
        count = len(person.waypoints)
        here = (person.x, person.y)
        for tried in range(count):
            goal = person.waypoints[(person.then + tried) % count]
            route = self.routes.route(person.leg_from, goal)
            if route is None:
                continue
            rest = route[1:]
            if len(rest) and here != person.leg_from and not self._clear(here, rest[0]):
                rest = np.vstack([person.route, route[:1], rest]) if len(person.route) else \
                    np.vstack([route[:1], rest])
            person.then, person.goal = (person.then + tried + 1) % count, goal
            person.returning = False
            person.route, person.gait, person.waited = rest, Gait.WALKING, 0.0
            person.trail = [here]
            return True
        person.gait, person.route = Gait.STANDING, np.zeros((0, 2))
        return False

    def _clear(self, start: Point, end: np.ndarray) -> bool:
        """Whether a person walks from ``start`` to ``end`` in a straight line clear of walls."""
        grid = self.routes.planner.grid
        return bool(line_clear(self._clearance, grid.origin_x, grid.origin_y, grid.resolution,
                                float(start[0]), float(start[1]), float(end[0]), float(end[1]),
                                self.settings.radius + 0.05))

    def _turn_back(self, person: Person) -> None:
        """Blocked for too long: walk back the way they came, to try again after a pause.

        The way they gave up becomes the way back should they turn again, so a person going to
        and fro on a leg always ends at one of its two ends (where routes are planned already).
        Blocked where they set off, they have no way back: they go on to the next waypoint.
        """
        here = (person.x, person.y)
        back = [here, *reversed(person.trail)]
        given_up = [(float(x), float(y)) for x, y in person.route]
        person.route = np.array(back[1:], dtype=np.float64).reshape(-1, 2)
        person.trail = [*reversed(given_up), here]
        near = math.dist(back[-1], person.leg_from) <= ARRIVED_NEAR
        person.leg_from, person.goal = person.goal, person.leg_from if near else back[-1]
        count = len(person.waypoints)
        if math.dist(back[0], back[-1]) <= 0.01:  # nowhere to go back to
            person.returning = False
        else:
            person.returning = not person.returning
            person.then = (person.then + (-1 if person.returning else 1)) % count
        person.gait, person.waited = Gait.WALKING, 0.0
