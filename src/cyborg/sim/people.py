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
it reached (within :data:`ARRIVED_NEAR`). And people make room for robots
(:mod:`cyborg.sim.room_for_robots`): they step away from a robot's body, out of the way of a
robot that drives at them, off the way a robot that stands waits to take; a person walking
on their way past a robot that stands walks on. Nobody pauses in a doorway or a passage too
narrow for a robot to pass them (:meth:`Crowd.narrow`): they walk on at once.

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
from collections.abc import Callable, Sequence
from typing import NamedTuple

import numpy as np

from cyborg.nav.planner import Planner
from cyborg.sim.bodies import outline_points
from cyborg.sim.crowd_geometry import in_the_way, line_clear
from cyborg.sim.people_routes import Point, RouteBook
from cyborg.sim.person import Gait, PeopleSettings, Person, PersonPlan
from cyborg.sim.room_for_robots import ROOM, RoomForRobots

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
WALK_PERIOD = 0.2
"""Seconds between two steps of the crowd: 30 cm at 1.5 m/s, fine enough for walking people
and half the work of stepping them with the robots' 10 Hz sensors."""
ARRIVED_NEAR = 1.5
"""Metres from a waypoint within which a person blocked on the way counts as arrived there:
someone else stands on it (a robot, a person pausing)."""
NO_ROBOTS = np.zeros((0, 3))
"""No robots, as circles (x, y, radius)."""
NO_WAY = np.zeros((0, 2))
"""The way of a robot that means to drive nowhere."""
NARROW_LOOK = 0.4
"""Metres around a person within which :meth:`Crowd.narrow` looks for room to pass them."""
OCTAGON = np.array([[math.cos(k * math.pi / 4), math.sin(k * math.pi / 4)] for k in range(8)])
"""A regular octagon of circumradius 1, counter-clockwise."""


class Crowd(RoomForRobots):
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
        # a robot passes a person where the way is wider than both and the room kept between
        self._passing = s.radius + ROOM / 2 + planner.lethal
        self._way_room = planner.lethal + s.radius + ROOM  # from a robot's way to a person
        for person in self.people:
            self._leave(person)
        # the octagon's edges touch the circle of `radius`, so the body is at least that round
        self._octagon = OCTAGON * (s.radius / math.cos(math.pi / 8))
        self._samples = outline_points(self._octagon, 0.1)  # around a body, from its centre
        self._owed = 0.0  # seconds not walked yet (see :meth:`due`)

    def __len__(self) -> int:
        """How many people walk."""
        return len(self.people)

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

    def beside(self, planner: Planner, outline: np.ndarray, dt: float, reach: float,
               speed: float = math.inf,
               way: Callable[[], np.ndarray] = lambda: NO_WAY) -> Meeting:
        """Walk ``dt`` s around one robot and say what it meets.

        ``outline`` is K x 2, its first and last corners the front edge's, as
        :meth:`~cyborg.nav.footprint.Footprint.polygon` gives them; ``speed`` the robot's
        (m/s; by default it counts as driving), ``way`` gives the way it means to drive (see
        :meth:`advance`; asked only when people walk).

        A robot whose ``planner`` is not the crowd's has switched maps: it meets nobody, and
        nobody walks.
        """
        if planner is not self.routes.planner:
            return NOBODY
        middle = outline.sum(axis=0) / len(outline)
        walked = self.due(dt)
        if walked:
            front = (outline[0] + outline[-1]) / 2 - middle  # the middle of the front edge
            self.advance(walked, [outline], [math.atan2(front[1], front[0])], [speed], [way()])
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
                headings: Sequence[float] = (), speeds: Sequence[float] = (),
                ways: Sequence[np.ndarray] = ()) -> None:
        """Walk everyone ``dt`` seconds, keeping clear of ``robots`` (outlines, K x 2 each).

        With the robots' ``headings`` (rad), people out of their way ahead too; with their
        ``speeds`` (m/s), people walking on their way pass in front of one standing still
        (slower than :data:`~cyborg.sim.room_for_robots.STILL`; a robot without a speed
        counts as driving). With their
        ``ways`` ((M, 2) points along the way each means to drive, empty for none; see
        :meth:`~cyborg.sim.navigator.Navigator.way_ahead`), people keep off those instead
        of the line ahead (:meth:`_keep_off_ways`).
        """
        self.time += dt
        circles = np.empty((len(robots), 3))
        for index, outline in enumerate(robots):
            middle = outline.sum(axis=0) / len(outline)
            circles[index, :2] = middle
            circles[index, 2] = math.sqrt(float(np.max(np.sum((outline - middle) ** 2, axis=1))))
        stepped_off = self._keep_off_ways(dt, ways, speeds, circles) if ways else set()
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
            if id(person) not in stepped_off:
                walking.append(person)
        if walking:
            blocked = self._blocked(walking, circles) | self._onto_ways(walking, dt, ways,
                                                                         speeds)
            for person, stopped in zip(walking, blocked, strict=True):
                self._walk(person, dt, bool(stopped), circles)
        if len(circles):
            without_way = [not (index < len(ways) and len(ways[index]))
                           for index in range(len(circles))]
            self._make_room(dt, circles, [heading if free else math.nan for heading, free
                                          in zip(headings, without_way, strict=False)],
                            speeds)

    def _walk(self, person: Person, dt: float, blocked: bool,
              robots: np.ndarray = NO_ROBOTS) -> None:
        """Walk ``person`` on along their route for ``dt`` s, or wait when ``blocked``.

        Round a corner they go on only when the way ahead after it is free (of people and of
        ``robots``, (M, 3) circles), as it was checked before the step in the way they faced.
        """
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
                if left > 0.0 and len(person.route) and self._turned_into(person, robots):
                    break  # round the corner, someone is in the way: the next step waits
            else:
                person.x += (tx - person.x) * left / gap
                person.y += (ty - person.y) * left / gap
                left = 0.0
        if len(person.route) == 0:
            self._arrive(person)

    def _turned_into(self, person: Person, robots: np.ndarray) -> bool:
        """Whether, facing the next corner of their route, someone is in ``person``'s way."""
        ahead = person.route[0]
        if (ahead[0], ahead[1]) == (person.x, person.y):
            return False
        person.heading = math.atan2(ahead[1] - person.y, ahead[0] - person.x)
        return bool(self._blocked([person], robots)[0])

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
        """Pause at the waypoint (or as near it as they got), then go on to the next.

        Where the way is :meth:`narrow` there is no pause: they go on at once.
        """
        s = self.settings
        person.gait = Gait.PAUSING
        person.leg_from = person.goal
        person.trail = person.trail[-1:] if len(person.route) == 0 else []
        pause = float(self._random.uniform(s.min_pause, s.max_pause))
        person.until = self.time + (0.0 if self.narrow(person.x, person.y) else pause)

    def narrow(self, x: float, y: float) -> bool:
        """Whether ``(x, y)`` lies in a passage too narrow for a robot to pass a person there.

        A doorway, a narrow corridor: within :data:`NARROW_LOOK` m of the point no place
        is further from the walls than half the width a robot passing a person needs (both
        bodies and half of :data:`~cyborg.sim.room_for_robots.ROOM`).
        """
        grid = self.routes.planner.grid
        row, column = grid.cell(x, y)
        reach = math.ceil(NARROW_LOOK / grid.resolution)
        window = self._clearance[max(row - reach, 0):row + reach + 1,
                                 max(column - reach, 0):column + reach + 1]
        return window.size == 0 or float(window.max()) < self._passing

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

    def _clear(self, start: Point, end: np.ndarray, spare: float = 0.05) -> bool:
        """Whether a person walks from ``start`` to ``end`` in a straight line clear of walls.

        Clear: their body and ``spare`` m from every wall, or, from a start closer than that
        (someone squeezed past), no closer than there: else they could never move again.
        """
        grid = self.routes.planner.grid
        here = grid.clearance_at(self._clearance, float(start[0]), float(start[1]))
        return bool(line_clear(self._clearance, grid.origin_x, grid.origin_y, grid.resolution,
                                float(start[0]), float(start[1]), float(end[0]), float(end[1]),
                                min(self.settings.radius + spare, here - 1e-6)))

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
