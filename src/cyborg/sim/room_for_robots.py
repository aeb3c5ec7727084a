"""How people keep out of robots' way: making room, stepping off a waiting robot's way.

:class:`RoomForRobots` is the part of :class:`~cyborg.sim.people.Crowd` that deals with the
robots among the people (see :mod:`cyborg.sim.people` for the rules); the crowd walks, this
moves people aside. Whoever is closer than :data:`ROOM` to a robot's body steps away from it;
whoever stands ahead of a driving robot steps aside; whoever is on the way a standing robot
waits to take steps off it; nobody walks onto that way while the robot stands.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from cyborg.sim.crowd_geometry import in_robots_way, way_off
from cyborg.sim.people_routes import Point, RouteBook
from cyborg.sim.person import Gait, PeopleSettings, Person

ROOM = 0.3
"""Metres people keep between their bodies and a robot's when they can: closer, they step
away from it (the robot's body counted as the circle around its outline)."""
SIDESTEPS = (0.0, math.pi / 4, -math.pi / 4, math.pi / 2, -math.pi / 2)
"""Turns (rad) from straight away from a robot that a person making room for it tries."""
AHEAD = 2.5
"""Metres ahead of a robot within which people step out of its way."""
REJOIN = 0.5
"""Metres within which a person who stepped aside passes over a corner of their way in sight
of the next (stepping aside again and again, they would otherwise queue a corner per step)."""
POCKET = 1.0
"""Metres a person who found no way on beside a robot's way (a pocket, a niche) goes on along
the way before stepping aside again."""
REFUGE = 6.0
"""Metres a person on a waiting robot's way, with no step aside free, walks at most to a place
off it (:meth:`RoomForRobots._refuge`)."""
STILL = 0.05
"""Metres per second under which a robot counts as standing still: people walking on their
way pass in front of it instead of stepping aside (:meth:`Crowd.advance`)."""


class RoomForRobots:
    """People moving out of robots' way: the part of the crowd that knows the robots."""

    people: list[Person]
    settings: PeopleSettings
    time: float
    _way_room: float  # metres from a robot's way within which a person is on it
    _clearance: np.ndarray  # metres from walls, on the crowd's planner's grid
    routes: RouteBook

    @property
    def positions(self) -> np.ndarray:
        """Every person's position, (N, 2) metres in the map frame."""
        return np.array([(p.x, p.y) for p in self.people], dtype=np.float64).reshape(-1, 2)

    def _clear(self, start: Point, end: np.ndarray, spare: float = 0.05) -> bool:
        """Whether a person walks from ``start`` to ``end`` clear of walls (the crowd's)."""
        raise NotImplementedError

    def _keep_off_ways(self, dt: float, ways: Sequence[np.ndarray], speeds: Sequence[float],
                       robots: np.ndarray) -> set[int]:
        """People on the way of a robot that stands step off it; the ``id`` s of those who did.

        On the way means closer to one of its points than the robot's circumscribed radius,
        their body and :data:`ROOM`: where the robot's wait for them would not end (a robot
        that drives has people step out of the way as it comes, :meth:`_make_room`). They step
        aside from it; where no step aside is free (a corridor, a doorway) they walk to the
        nearest place off every such way (:meth:`_refuge`, ``robots`` being the robots' bodies
        as (M, 3) circles) and keep to that until there; with none in reach, on along the way
        (away from the robot, to where there is room aside), squeezing past other people; with
        nothing free, a pause ends.
        """
        moved: set[int] = set()
        standing = [way for index, way in enumerate(ways)
                    if len(way) >= 2 and self._stands(index, speeds)]
        for way in standing:
            for person in self.people:
                gaps = np.hypot(way[:, 0] - person.x, way[:, 1] - person.y)
                nearest = int(np.argmin(gaps))
                if gaps[nearest] >= self._way_room or id(person) in moved:
                    continue
                if person.pocket and math.dist(person.pocket, (person.x, person.y)) > POCKET:
                    person.pocket = None  # well on along the way: aside again
                moved.add(id(person))
                step = person.speed * dt
                if person.refuge is None:
                    if self._aside(person, way, float(gaps[nearest]), nearest, step):
                        continue
                    person.refuge = self._refuge(person, standing, robots)
                if person.refuge is not None:
                    self._to_refuge(person, step)
                    continue
                if self._step_off(person, way, nearest, step):
                    continue
                if person.gait is Gait.PAUSING:
                    person.until = self.time  # no room: walk on when the way lets them
                else:
                    moved.discard(id(person))  # no room: on their way, if it is free
        for person in self.people:
            if id(person) not in moved:
                person.refuge = None  # off every way that a robot waits to take
        return moved

    def _refuge(self, person: Person, ways: list[np.ndarray],
                robots: np.ndarray) -> np.ndarray | None:
        """The walk to the nearest place off every one of ``ways``, within :data:`REFUGE` m.

        Off a way as :meth:`_keep_off_ways` counts it, over the floor a person fits on, round
        the robots (``robots``: (M, 3) circles of their bodies, kept a body and :data:`ROOM`
        off); None when there is none.
        """
        grid = self.routes.planner.grid
        bodies = robots.copy()
        bodies[:, 2] += self.settings.radius + ROOM
        walk = way_off(self._clearance, grid.origin_x, grid.origin_y, grid.resolution,
                       person.x, person.y, self.settings.radius, REFUGE, np.concatenate(ways),
                       self._way_room + grid.resolution, bodies)
        return walk if len(walk) else None

    def _to_refuge(self, person: Person, step: float) -> None:
        """One step of ``person`` along their walk to a refuge (cell to cell: clear of walls).

        Round its corners: a straight line to where the step ends could cut one.
        """
        assert person.refuge is not None
        here = np.array((person.x, person.y))
        walk = person.refuge
        while len(walk) and step > 0.0:
            gap = float(np.hypot(*(walk[0] - here)))
            if gap > step:
                here = here + (walk[0] - here) * (step / gap)
                break
            here, walk, step = walk[0], walk[1:], step - gap
        person.refuge = walk if len(walk) else None
        self._move(person, (float(here[0]), float(here[1])))

    def _aside(self, person: Person, way: np.ndarray, gap: float, nearest: int,
               step: float) -> bool:
        """One step of ``person`` aside from ``way``; whether one was free.

        ``gap`` is their distance to the way, ``nearest`` the index of its point nearest to
        them. Aside (the side away from the robot, at the way's first point, first) counts
        only when it takes them almost a whole step further from the way (a bend of the way
        round them, or a wall, leaves no such step). Squeezing past other people.
        """
        ux, uy = way[min(nearest + 1, len(way) - 1)] - way[max(nearest - 1, 0)]
        norm = math.hypot(ux, uy) or 1.0
        ux, uy = ux / norm, uy / norm
        robot = way[0]
        sides = sorted((1.0, -1.0), key=lambda side: -math.hypot(
            person.x - side * uy - robot[0], person.y + side * ux - robot[1]))
        for side in sides if person.pocket is None else ():
            to = (person.x - side * uy * step, person.y + side * ux * step)
            if (float(np.min(np.hypot(way[:, 0] - to[0], way[:, 1] - to[1])))
                    >= gap + 0.8 * step and self._free(person, to, squeeze=True)):
                self._move(person, to)
                return True
        return False

    def _step_off(self, person: Person, way: np.ndarray, nearest: int, step: float) -> bool:
        """One step of ``person`` on along ``way``, off it where there is room; whether free.

        ``nearest`` is the index of its point nearest to them. They walk towards a point more
        than a step further on than the nearest, following its bends to where there is room
        aside, brushing walls; from a pocket beside the way, back to it first.
        """
        spacing = math.hypot(*(way[1] - way[0])) or 1.0
        onward = min(nearest + 2 + int(step / spacing), len(way) - 1)
        dx, dy = way[onward, 0] - person.x, way[onward, 1] - person.y  # on along the way
        length = math.hypot(dx, dy)
        if length < 1e-9:
            return False
        to = (person.x + dx * min(1.0, step / length), person.y + dy * min(1.0, step / length))
        if not self._free(person, to, squeeze=True):
            # in a pocket beside the way: back to the way, and on along it without stepping
            # aside into the pocket again until well on
            person.pocket = (person.x, person.y)
            dx, dy = way[nearest, 0] - person.x, way[nearest, 1] - person.y
            length = math.hypot(dx, dy)
            if length < 1e-9:
                return False
            to = (person.x + dx * min(1.0, step / length),
                  person.y + dy * min(1.0, step / length))
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
        a pause; but someone walking on their way passes in front of a robot standing still,
        and someone walking to a refuge off a waiting robot's way (:meth:`_refuge`, never
        nearer to a robot than where they set off) keeps to that. A robot stuck beside a
        person would be stuck for good.
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
                if person.refuge is None:
                    self._room_for(person, cx, cy, need,
                                   None if math.isnan(heading) else heading, driving, dt)

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
        """Put ``person`` at ``to``, a step off their way: the way back and on pass here.

        Here joins the way back only where its last corner is out of sight from ``to``: steps
        to and fro beside a robot leave a way back as short as the way they came.
        """
        here = (person.x, person.y)
        if not person.trail or not self._clear(to, np.array(person.trail[-1]), 0.0):
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
