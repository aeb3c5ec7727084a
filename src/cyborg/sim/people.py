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
than :data:`ROOM` to a robot's body steps away from it, if walls and others let them; whoever
stands ahead of a robot steps aside, or, with no room aside, walks on (a pause ends). A person
walking on their way past a robot that stands still walks on rather than side-step (stepping
aside from a robot waiting for them, and back onto their way, they would stand there for
good); and nobody pauses in a doorway or a passage too narrow for a robot to pass them
(:meth:`Crowd.narrow`): they pause a step further on, where there is room.

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
NO_WAY = np.zeros((0, 2))
"""The way of a robot that means to drive nowhere."""
REJOIN = 0.5
"""Metres within which a person who stepped aside passes over a corner of their way in sight
of the next (stepping aside again and again, they would otherwise queue a corner per step)."""
STILL = 0.05
"""Metres per second under which a robot counts as standing still: people walking on their
way pass in front of it instead of stepping aside (:meth:`Crowd.advance`)."""
NARROW_LOOK = 0.4
"""Metres around a person within which :meth:`Crowd.narrow` looks for room to pass them."""
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

    def beside(self, planner: Planner, outline: np.ndarray, dt: float, reach: float,
               speed: float = math.inf, way: np.ndarray = NO_WAY) -> Meeting:
        """Walk ``dt`` s around one robot and say what it meets.

        ``outline`` is K x 2, its first and last corners the front edge's, as
        :meth:`~cyborg.nav.footprint.Footprint.polygon` gives them; ``speed`` the robot's
        (m/s; by default it counts as driving), ``way`` the way it means to drive (see
        :meth:`advance`).

        A robot whose ``planner`` is not the crowd's has switched maps: it meets nobody, and
        nobody walks.
        """
        if planner is not self.routes.planner:
            return NOBODY
        middle = outline.sum(axis=0) / len(outline)
        walked = self.due(dt)
        if walked:
            front = (outline[0] + outline[-1]) / 2 - middle  # the middle of the front edge
            self.advance(walked, [outline], [math.atan2(front[1], front[0])], [speed], [way])
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
        (slower than :data:`STILL`; a robot without a speed counts as driving). With their
        ``ways`` ((M, 2) points along the way each means to drive, empty for none; see
        :meth:`~cyborg.sim.navigator.Navigator.way_ahead`), people keep off those instead
        of the line ahead (:meth:`_keep_off_ways`).
        """
        self.time += dt
        stepped_off = self._keep_off_ways(dt, ways, speeds) if ways else set()
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
        circles = np.empty((len(robots), 3))
        for index, outline in enumerate(robots):
            middle = outline.sum(axis=0) / len(outline)
            circles[index, :2] = middle
            circles[index, 2] = math.sqrt(float(np.max(np.sum((outline - middle) ** 2, axis=1))))
        if walking:
            blocked = self._blocked(walking, circles) | self._onto_ways(walking, dt, ways,
                                                                         speeds)
            for person, stopped in zip(walking, blocked, strict=True):
                self._walk(person, dt, bool(stopped))
        if len(circles):
            without_way = [not (index < len(ways) and len(ways[index]))
                           for index in range(len(circles))]
            self._make_room(dt, circles, [heading if free else math.nan for heading, free
                                          in zip(headings, without_way, strict=False)],
                            speeds)

    # ------------------------------------------------------------------ robots' ways
    def _keep_off_ways(self, dt: float, ways: Sequence[np.ndarray],
                       speeds: Sequence[float]) -> set[int]:
        """People on the way of a robot that stands step off it; the ``id`` s of those who did.

        On the way means closer to one of its points than the robot's circumscribed radius,
        their body and :data:`ROOM`: where the robot's wait for them would not end (a robot
        that drives has people step out of the way as it comes, :meth:`_make_room`). They step
        aside from it, else on along it (away from the robot, to where there is room aside),
        squeezing past other people; with neither free, a pause ends.
        """
        moved: set[int] = set()
        for index, way in enumerate(ways):
            if len(way) < 2 or not self._stands(index, speeds):
                continue
            for person in self.people:
                gaps = np.hypot(way[:, 0] - person.x, way[:, 1] - person.y)
                nearest = int(np.argmin(gaps))
                if gaps[nearest] >= self._way_room:
                    continue
                moved.add(id(person))
                if self._step_off(person, way, float(gaps[nearest]), nearest,
                                  person.speed * dt):
                    continue
                if person.gait is Gait.PAUSING:
                    person.until = self.time  # no room: walk on when the way lets them
                else:
                    moved.discard(id(person))  # no room: on their way, if it is free
        return moved

    def _step_off(self, person: Person, way: np.ndarray, gap: float, nearest: int,
                  step: float) -> bool:
        """One step of ``person`` off ``way``: aside, or on along it; whether one was free.

        ``gap`` is their distance to the way, ``nearest`` the index of its point nearest to
        them. Aside (the side away from the robot, at the way's first point, first) counts
        only when it takes them almost a whole step further from the way (a bend of the way
        round them, or a wall, leaves no such step); else they walk on along it, towards a point
        more than a step further on than the nearest, following its bends to where there is
        room aside. Squeezing past other people, brushing walls.
        """
        ux, uy = way[min(nearest + 1, len(way) - 1)] - way[max(nearest - 1, 0)]
        norm = math.hypot(ux, uy) or 1.0
        ux, uy = ux / norm, uy / norm
        robot = way[0]
        sides = sorted((1.0, -1.0), key=lambda side: -math.hypot(
            person.x - side * uy - robot[0], person.y + side * ux - robot[1]))
        for side in sides:
            to = (person.x - side * uy * step, person.y + side * ux * step)
            if (float(np.min(np.hypot(way[:, 0] - to[0], way[:, 1] - to[1])))
                    >= gap + 0.8 * step and self._free(person, to, squeeze=True)):
                self._move(person, to)
                return True
        spacing = math.hypot(*(way[1] - way[0])) or 1.0
        onward = min(nearest + 2 + int(step / spacing), len(way) - 1)
        dx, dy = way[onward, 0] - person.x, way[onward, 1] - person.y  # on along the way
        length = math.hypot(dx, dy)
        if length < 1e-9:
            return False
        to = (person.x + dx * min(1.0, step / length), person.y + dy * min(1.0, step / length))
        if not self._free(person, to, squeeze=True):
            return False
        self._move(person, to)
        return True

    @staticmethod
    def _stands(index: int, speeds: Sequence[float]) -> bool:
        """Whether robot ``index`` stands (slower than :data:`STILL`; without a speed, no)."""
        return index < len(speeds) and abs(speeds[index]) < STILL

    def _onto_ways(self, walking: list[Person], dt: float, ways: Sequence[np.ndarray],
                   speeds: Sequence[float]) -> np.ndarray:
        """For each of ``walking``: whether their next step enters a standing robot's way.

        They wait for it to be free: the way is taken, as by a body. (Someone on it already,
        with no room to step off, walks on: anything but stand there.)
        """
        onto = np.zeros(len(walking), bool)
        for index, way in enumerate(ways):
            if len(way) < 2 or not self._stands(index, speeds):
                continue
            for k, person in enumerate(walking):
                if len(person.route) == 0 or float(np.min(np.hypot(
                        way[:, 0] - person.x, way[:, 1] - person.y))) < self._way_room:
                    continue
                tx, ty = person.route[0]
                gap = math.hypot(tx - person.x, ty - person.y)
                share = min(1.0, person.speed * dt / gap) if gap > 1e-9 else 0.0
                x, y = person.x + (tx - person.x) * share, person.y + (ty - person.y) * share
                onto[k] |= bool(np.min(np.hypot(way[:, 0] - x, way[:, 1] - y))
                                < self._way_room)
        return onto

    def _make_room(self, dt: float, robots: np.ndarray, headings: Sequence[float],
                   speeds: Sequence[float]) -> None:
        """People step out of robots' way, where walls and other people let them.

        Whoever is closer than :data:`ROOM` to a robot's body steps away from it; whoever is
        ahead of it (within :data:`AHEAD` along its heading, and its body and ours and
        :data:`ROOM` aside) steps aside, else further ahead, and with no room for either ends
        a pause; but someone walking on their way passes in front of a robot standing still.
        A robot stuck beside a person would be stuck for good.
        """
        s = self.settings
        for index, (cx, cy, radius) in enumerate(robots):
            need = radius + s.radius + ROOM
            touched = in_robots_way(self.positions,  # as the robots before this one left them
                                    cx, cy, need,
                                    headings[index] if index < len(headings) else math.nan,
                                    AHEAD)
            driving = index >= len(speeds) or abs(speeds[index]) >= STILL
            heading = headings[index] if index < len(headings) else math.nan
            for person in (self.people[k] for k in np.flatnonzero(touched)):
                self._room_for(person, cx, cy, need, None if math.isnan(heading) else heading,
                               driving, dt)

    def _room_for(self, person: Person, cx: float, cy: float, need: float,
                  heading: float | None, driving: bool, dt: float) -> None:
        """``person`` steps out of the way of a robot at ``(cx, cy)`` heading ``heading``.

        ``need`` is the gap (m, centre to centre) the person keeps from the robot; ``driving``
        whether it moves (else someone walking on their way walks on past it).
        """
        dx, dy = person.x - cx, person.y - cy
        distance = math.hypot(dx, dy)
        passing = person.gait is Gait.WALKING and not driving
        if heading is not None and not passing:
            ux, uy = math.cos(heading), math.sin(heading)
            along, across = dx * ux + dy * uy, uy * dx - ux * dy
            if 0.0 < along <= AHEAD and abs(across) < need:
                side = heading + (-math.pi / 2 if across >= 0 else math.pi / 2)
                if (not self._step_away(person, side, person.speed * dt,
                                        (0.0, math.pi / 4, math.pi / 2))
                        and person.gait is Gait.PAUSING):
                    person.until = self.time  # no room aside: walk on instead
                return
        if distance >= need:
            return
        if distance < 1e-9:
            dx, dy, distance = -math.cos(person.heading), -math.sin(person.heading), 1.0
        self._step_away(person, math.atan2(dy, dx), min(need - distance, person.speed * dt),
                        SIDESTEPS)

    def _step_away(self, person: Person, away: float, step: float,
                   turns: tuple[float, ...], squeeze: bool = False) -> bool:
        """Step ``step`` m towards ``away`` (rad), or the first of ``turns`` from it that is free.

        Each turn is tried to the left and then to the right. Whether a step was free; with
        ``squeeze``, of walls only (people squeeze past each other to clear a robot's way).
        """
        for turn in turns:
            for sign in ((1.0, -1.0) if turn else (1.0,)):
                to = (person.x + step * math.cos(away + sign * turn),
                      person.y + step * math.sin(away + sign * turn))
                if self._free(person, to, squeeze):
                    self._move(person, to)
                    return True
        return False

    def _move(self, person: Person, to: Point) -> None:
        """Put ``person`` at ``to``, a step off their way: the way back and on pass here."""
        here = (person.x, person.y)
        person.trail.append(here)
        route = person.route  # corners close by in sight of the next are passed over
        while (len(route) > 1 and math.dist(route[0], to) <= REJOIN
               and self._clear(to, route[1], 0.0)):
            route = route[1:]
        if len(route) and not self._clear(to, route[0], 0.0):
            route = np.vstack([here, route])
        person.route = route
        person.x, person.y = to

    def _free(self, person: Person, to: Point, squeeze: bool = False) -> bool:
        """Whether ``person`` may step to ``to``: clear of walls and other people.

        With ``squeeze``, of walls only, brushing past them.
        """
        s = self.settings
        if not self._clear((person.x, person.y), np.array(to), 0.0 if squeeze else 0.05):
            return False
        return squeeze or not any(other is not person and math.hypot(other.x - to[0],
                                                                      other.y - to[1])
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
        bodies and half of :data:`ROOM`).
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

        Clear: their body and ``spare`` m from every wall.
        """
        grid = self.routes.planner.grid
        return bool(line_clear(self._clearance, grid.origin_x, grid.origin_y, grid.resolution,
                                float(start[0]), float(start[1]), float(end[0]), float(end[1]),
                                self.settings.radius + spare))

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
