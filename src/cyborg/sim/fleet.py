"""Several simulated robots on one map, stepped together on one clock.

A :class:`Fleet` holds one :class:`~cyborg.sim.simulator.Simulator` per robot, all on the same
map (sharing its planner), and steps them in lockstep: one physics step of the fleet is one
step of each robot, in turn, so they share simulated time and one ``/clock``. Before a robot
steps it meets the others (:meth:`Simulator.meet`): their outlines where they stand now are
obstacles to its laser, its drive, its navigator and its motion check. Since each robot moves
while the others stand still, and its drive refuses any step that would make its body overlap
another's (:mod:`cyborg.sim.bodies`), robots never overlap: one blocked by another stops, and
its navigator waits and replans around it as ARNL does around any obstacle, or gives up;
two that meet head-on settle it, one making way for the other (:mod:`cyborg.sim.giving_way`).
At the physics steps between two sensor steps only the drive needs the others, and only those
near enough to touch it (:data:`CONTACT_MARGIN`): a robot that stands keeps its outline (the
same array), and one alone pays nothing for the others.

The robots start at distinct free poses (:func:`choose_starts`): the first where a lone robot
would (:func:`cyborg.sim.start.choose_start`), the others at the free points nearest to it,
:data:`START_SPACING` apart, clear of walls by the planner's margin, off the map's goals and
docks (a robot waiting there would block them), and reachable from the first.

A :class:`~cyborg.sim.loop.PacedLoop` steps the fleet; :func:`robot_loops` gives each robot
its share of that loop (a :class:`~cyborg.sim.loop.RobotLoop`), which is what its bus node
(:class:`~cyborg.sim.node.SimulatorNode`) needs::

    fleet = Fleet(read_map("campus.map"), 3)
    loop = PacedLoop(fleet, speed=10)
    for node, robot_loop in zip(nodes, robot_loops(loop)):
        SimulatorNode(node, robot_loop, ...)
    loop.start()
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np
from scipy import ndimage

from cyborg.nav.arnl_map import ArnlMap
from cyborg.nav.geometry import Pose2D
from cyborg.nav.planner import Planner
from cyborg.sim.battery import Battery
from cyborg.sim.bodies import KEEP_CLEAR, braking_outline, grown, halves
from cyborg.sim.giving_way import WayGiving
from cyborg.sim.loop import PacedLoop, SimulationLock
from cyborg.sim.people import NOBODY, Crowd, Meeting
from cyborg.sim.simulator import SimSettings, Simulator
from cyborg.sim.start import START_MARGIN, StartChoice, choose_start

CONTACT_MARGIN = 0.5
"""Metres beyond two bodies' reach within which one robot's drive checks another's outline
at every physics step (a step at top speed is 4 cm); further ones only its sensors meet."""
MAX_ROBOTS = 16
"""The most robots a fleet has (as many as the web monitor follows)."""
START_SPACING = 1.5
"""Metres between the centres of two robots' starts: room to turn and to drive off."""
GOAL_SPACING = 1.0
"""Metres a start keeps from the map's goals, docks and homes (but the first robot's)."""


def choose_starts(arnl_map: ArnlMap, planner: Planner, count: int,
                  start: Pose2D | str | None = None) -> list[StartChoice]:
    """Where ``count`` robots start on ``arnl_map``: distinct free poses (see the module doc).

    The first is :func:`~cyborg.sim.start.choose_start`'s (``start`` as there); all face its
    way. ValueError, saying how many fit, when the map has no room for ``count``.
    """
    if count < 1:
        raise ValueError(f"robots: a fleet has 1 robot or more, not {count}")
    first = choose_start(arnl_map, planner, start)
    choices = [first]
    if count == 1:
        return choices
    grid, clearance = planner.grid, planner.clearance
    free = clearance >= planner.lethal + START_MARGIN
    labels, _regions = ndimage.label(free)
    rows, columns = np.nonzero(free)
    xs = grid.origin_x + (columns + 0.5) * grid.resolution
    ys = grid.origin_y + (rows + 0.5) * grid.resolution
    if len(xs) == 0:
        raise ValueError(f"robots: {arnl_map.source} has room for 1 robot, not {count}")
    origin = first.pose
    distance = np.hypot(xs - origin.x, ys - origin.y)
    nearest = int(np.argmin(distance))
    region = labels[rows[nearest], columns[nearest]]  # where the first robot can drive
    keep = labels[rows, columns] == region
    for item in arnl_map.goals() + arnl_map.homes():
        keep &= np.hypot(xs - item.x, ys - item.y) >= GOAL_SPACING
    order = np.argsort(distance, kind="stable")
    order = order[keep[order]]
    taken = [(origin.x, origin.y)]
    for index in order:
        x, y = float(xs[index]), float(ys[index])
        if all(np.hypot(x - tx, y - ty) >= START_SPACING for tx, ty in taken):
            taken.append((x, y))
            pose = Pose2D(x, y, origin.theta)
            choices.append(StartChoice(pose, f"{arnl_map.source}: robot {len(taken)} starts "
                                             f"at the free point ({x:.2f}, {y:.2f}) nearest to "
                                             "the first robot's start"))
            if len(choices) == count:
                return choices
    raise ValueError(f"robots: {arnl_map.source} has room for {len(choices)} robots "
                     f"({START_SPACING:g} m apart, off goals and docks, where the first can "
                     f"drive), not {count}")


class Fleet:
    """``count`` simulated robots on ``arnl_map``, stepped together; see the module doc.

    ``start`` places the first robot (as :class:`Simulator`'s), ``settings`` are every robot's,
    ``charges`` their batteries' charges at the start (percent; default full). ValueError for a
    count out of 1..:data:`MAX_ROBOTS` or more robots than the map has room for.
    """

    def __init__(self, arnl_map: ArnlMap, count: int, start: Pose2D | str | None = None, *,
                 settings: SimSettings | None = None,
                 charges: Sequence[float] | None = None, planner: Planner | None = None) -> None:
        if not 1 <= count <= MAX_ROBOTS:
            raise ValueError(f"robots: a fleet has 1 to {MAX_ROBOTS} robots, not {count}")
        planner = planner or Planner(arnl_map)
        starts = choose_starts(arnl_map, planner, count, start)
        charges = list(charges) if charges is not None else [Battery.charge_percent] * count
        if len(charges) != count:
            raise ValueError(f"charges: {len(charges)} charges for {count} robots")
        self.simulators = [Simulator(arnl_map, choice.pose, settings,
                                     Battery(charge_percent=charge), planner)
                           for choice, charge in zip(starts, charges, strict=True)]
        self.start_choices = starts
        self._steps = 0
        self._grown = [grown(sim.base.footprint.polygon(), KEEP_CLEAR)
                       for sim in self.simulators]  # around each body, in its own frame
        self._sides = [halves(body) for body in self._grown]
        # centres further apart than this cannot touch within a physics step
        self._contact = 2 * max(sim.base.span for sim in self.simulators) + CONTACT_MARGIN
        self.crowd: Crowd | None = None  # people walking among the robots
        self.way_giving = WayGiving(count)  # robots that meet head-on settle it
        self._met: list[Meeting] = []
        self._touching: list[tuple[np.ndarray, ...]] = [()] * count  # people each may touch
        self._braking: list[tuple[Pose2D, float, np.ndarray] | None] = [None] * count

    @property
    def map(self) -> ArnlMap:
        """The map the fleet runs on (the first robot's, should one have switched)."""
        return self.simulators[0].map

    @property
    def time(self) -> float:
        """Simulated seconds since the start, the same for every robot."""
        return self.simulators[0].time

    @property
    def steps_per_sensor(self) -> int:
        """Physics steps per sensor step, the same for every robot."""
        return self.simulators[0].steps_per_sensor

    def step(self) -> None:
        """Advance every robot one physics step, each meeting the others where they are now.

        At each sensor step a robot also learns the points along the outline of the ground each
        other one covers until it stands, braking (:func:`~cyborg.sim.bodies.braking_outline`),
        which its navigator keeps clear of; the fleet's ``crowd``, if any, walks then, and each
        robot meets the people too.
        """
        sensing = self._steps % self.steps_per_sensor == 0  # as each simulator counts
        self._steps += 1
        sims = self.simulators
        poses = [sim.pose for sim in sims]  # set_pose may have moved one
        if sensing and self.crowd is not None:
            sim = self.simulators[0]
            walked = self.crowd.due(self.steps_per_sensor / sim.settings.physics_rate)
            if walked:
                self.crowd.advance(walked, [sim.outline for sim in sims],
                                   [sim.pose.theta for sim in self.simulators],
                                   [sim.base.speed for sim in self.simulators],
                                   [sim.way_ahead() for sim in self.simulators])
            self._met = [self.crowd.meeting(sim.pose.x, sim.pose.y, sim.laser.spec.range_max)
                         if sim.planner is self.crowd.routes.planner else NOBODY
                         for sim in self.simulators]  # people walk on the fleet's first map
        for index, sim in enumerate(self.simulators):
            met = self._met[index] if self._met else None
            if sensing:
                near = self._near(index, poses)
                placed_points = [self._braking_points(other) for other in near]
                if met:
                    placed_points.append(met.points)
                    self._touching[index] = within(met.bodies, sim.pose,
                                                   sim.base.span + CONTACT_MARGIN)
                points = np.concatenate(placed_points) if placed_points else np.zeros((0, 2))
                bodies = tuple(sims[other].outline for other in near)
                sim.meet(bodies + met.bodies if met else bodies, points,
                         met.circles if met else None)
            # the drive needs only the bodies it may touch this step (the same while they stand)
            touching = tuple(sims[other].outline  # kept while it stands, made when asked
                             for other in self._near(index, poses, self._contact))
            sim.base.others = touching + self._touching[index] if met else touching
            sim.step()
            poses[index] = sim.pose  # where the next robot meets it
        if sensing and len(self.simulators) > 1:
            self.way_giving.step(self.simulators, self.time)

    def _braking_points(self, index: int) -> np.ndarray:
        """Points along robot ``index``'s outline and braking way (kept while it stands)."""
        base = self.simulators[index].base
        key = (base.pose, base.speed)
        known = self._braking[index]
        if known is None or known[0] is not key[0] or known[1] != key[1]:
            points = braking_outline(self._grown[index], base.pose, base.speed,
                                     base.limits.acceleration, sides=self._sides[index])
            known = self._braking[index] = (base.pose, base.speed, points)
        return known[2]

    def _near(self, index: int, poses: list[Pose2D], reach: float | None = None) -> list[int]:
        """The indices of the robots on ``index``'s map within ``reach`` m (its laser's).

        ``poses`` are where the robots stand now.
        """
        sims = self.simulators
        sim, here = sims[index], poses[index]
        reach = sim.laser.spec.range_max + 1.0 if reach is None else reach
        x, y, world = here.x, here.y, sim.map
        return [number for number, there in enumerate(poses)
                if number != index and sims[number].map is world
                and math.hypot(there.x - x, there.y - y) <= reach]


def within(bodies: tuple[np.ndarray, ...], pose: Pose2D,
           reach: float) -> tuple[np.ndarray, ...]:
    """Those of ``bodies`` (outlines, K x 2 each) that come within ``reach`` m of ``pose``."""
    kept = []
    for body in bodies:
        middle = body.mean(axis=0)
        size = float(np.max(np.hypot(body[:, 0] - middle[0], body[:, 1] - middle[1])))
        if math.hypot(middle[0] - pose.x, middle[1] - pose.y) - size <= reach:
            kept.append(body)
    return tuple(kept)


class FleetRobotLoop:
    """One robot's share of a fleet's loop: a :class:`~cyborg.sim.loop.RobotLoop`.

    Its ``on_sensor`` callbacks run after each sensor step of the fleet with its own simulator;
    :meth:`stop` ends only those (the fleet goes on stepping, the robot stands where it is).
    """

    def __init__(self, loop: PacedLoop[Fleet], simulator: Simulator) -> None:
        self._loop = loop
        self.simulator = simulator
        self.on_sensor: list[Callable[[Simulator], None]] = []
        self.detached = False

    @property
    def lock(self) -> SimulationLock:
        """The fleet's lock: held by whoever touches any of its robots from another thread."""
        return self._loop.lock

    @property
    def error(self) -> BaseException | None:
        """What stopped the fleet's loop, if it failed."""
        return self._loop.error

    @property
    def running(self) -> bool:
        """Whether the fleet steps and this robot's callbacks run."""
        return self._loop.running and not self.detached

    def stop(self, timeout: float = 5.0) -> None:
        """Stop running this robot's callbacks (its node went); the others go on."""
        self.detached = True

    def sensed(self) -> None:
        """Run the callbacks after a sensor step (the fleet's thread, lock held)."""
        if not self.detached:
            for callback in list(self.on_sensor):
                callback(self.simulator)


def robot_loops(loop: PacedLoop[Fleet]) -> list[FleetRobotLoop]:
    """Each robot's share of ``loop``, in the fleet's order, their callbacks hooked in."""
    shares = [FleetRobotLoop(loop, sim) for sim in loop.simulator.simulators]

    def sensed(_fleet: Fleet) -> None:
        for share in shares:
            share.sensed()
    loop.on_sensor.append(sensed)
    return shares
