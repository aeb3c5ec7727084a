"""A simulated Pioneer LX on an ARNL map: drive, laser, bumpers, battery, dock, navigation.

The simulator owns simulated time. :meth:`Simulator.step` advances one physics step
(``physics_rate``, 50 Hz by default); every ``1 / sensor_rate`` seconds it also takes a laser
scan and lets the navigator and the docking sequence choose the next command. Nothing here waits
for the wall clock: :class:`cyborg.sim.loop.SimulationLoop` paces it (real time, ``--speed``
times faster, or as fast as possible)::

    sim = Simulator(read_map("AMROffice.map"), start="Dock")
    sim.go_to("room1")
    sim.run_until(lambda: sim.navigator.state.finished, timeout=600)
    sim.navigator.state, sim.pose, sim.battery.charge_percent

By hand, :meth:`Simulator.teleop` drives at a given speed and turn rate (within the limits of
:mod:`cyborg.sim.manual`, and never into what the robot knows: the command passes the motion
check of :mod:`cyborg.sim.motion_check`) until :meth:`Simulator.end_teleop`, and
:meth:`Simulator.set_pose` puts the robot somewhere else at once. Both end any goal.
Other robots on the map (:mod:`cyborg.sim.fleet`) are obstacles to it (:meth:`Simulator.meet`),
and so are people walking (:mod:`cyborg.sim.people`): a robot alone walks its ``crowd``.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from cyborg.nav.arnl_map import ArnlMap
from cyborg.nav.geometry import Pose2D, normalize_angle
from cyborg.nav.grid import MapGrid
from cyborg.nav.planner import Planner, PlanResult
from cyborg.sim.battery import Battery
from cyborg.sim.docking import Docking, DockPhase, DockSettings, DockState
from cyborg.sim.laser import Laser, LaserSpec
from cyborg.sim.manual import limit_command, placement_problem
from cyborg.sim.motion_check import Motion, Surroundings, safest_command, warm_up
from cyborg.sim.navigator import Navigator, NavigatorSettings, PathState
from cyborg.sim.people import Crowd
from cyborg.sim.robot import RobotBase
from cyborg.sim.start import StartChoice, choose_start

log = logging.getLogger("cyborg.sim")


@dataclass(frozen=True)
class SimSettings:
    """Step rates (Hz), the world grid (m per cell), the parts' settings, the noise seed."""

    physics_rate: float = 50.0  # Hz
    sensor_rate: float = 10.0  # Hz: laser, navigation, docking decisions
    world_resolution: float = 0.05  # metres per cell of the simulated world
    laser: LaserSpec = field(default_factory=LaserSpec)
    navigator: NavigatorSettings = field(default_factory=NavigatorSettings)
    dock: DockSettings = field(default_factory=DockSettings)
    seed: int = 0


@dataclass(frozen=True)
class Target:
    """A goal the robot was sent to: ``name`` ("" for a pose), pose, heading, description."""

    name: str
    pose: Pose2D
    use_heading: bool
    comment: str = ""


@dataclass(frozen=True)
class PreparedMap:
    """A map with what the simulator builds from it, ready to :meth:`Simulator.install_map`."""

    map: ArnlMap
    world: MapGrid
    planner: Planner
    base: RobotBase
    laser: Laser
    start_choice: StartChoice


class Simulator:
    """One robot in one map; see the module docstring.

    ``start`` is a pose or a goal name (see :meth:`load_map`); ``settings`` default to
    :class:`SimSettings` and ``battery`` to a full :class:`~cyborg.sim.battery.Battery`. Not
    thread-safe: under a :class:`~cyborg.sim.loop.SimulationLoop`, hold its lock.
    """

    def __init__(self, arnl_map: ArnlMap, start: Pose2D | str | None = None,
                 settings: SimSettings | None = None, battery: Battery | None = None,
                 planner: Planner | None = None) -> None:
        self.settings = settings or SimSettings()
        self.battery = battery or Battery()
        self.time = 0.0
        self.scans = 0
        self.ranges = np.zeros(0)
        self.hits = np.zeros((0, 2))
        self._steps = 0
        rates = self.settings.physics_rate / self.settings.sensor_rate
        self.steps_per_sensor = max(1, round(rates))
        self._command = (0.0, 0.0)
        self._after_dock: tuple[Pose2D, bool] | None = None
        self._teleop: tuple[float, float] | None = None
        self._target: Target | None = None
        self.others: tuple[np.ndarray, ...] = ()
        self._points = np.zeros((0, 2))
        self.people = np.zeros((0, 3))  # walking people as circles: x, y, radius (m)
        self.crowd: Crowd | None = None  # people walking around a robot alone
        warm_up()  # the motion check's kernel, before the robot moves
        self.load_map(arnl_map, start, planner)

    # ------------------------------------------------------------------ world
    def load_map(self, arnl_map: ArnlMap, start: Pose2D | str | None = None,
                 planner: Planner | None = None) -> None:
        """Switch to another map, with the robot standing where ``start`` says.

        ``start`` is a pose or a goal name; without one the robot starts at the map's home, or
        its dock, or a free point near the middle of the map (:mod:`cyborg.sim.start`). The
        choice is in ``start_choice`` and in the log: a warning when the map names no start, so
        ``cyborg sim`` shows it.
        """
        self.install_map(self.prepare_map(arnl_map, start, planner))

    def prepare_map(self, arnl_map: ArnlMap, start: Pose2D | str | None = None,
                    planner: Planner | None = None) -> PreparedMap:
        """Build what a map needs (grids, clearance, laser, start), leaving the simulation be.

        This is the slow half of :meth:`load_map`, which a caller can run without holding the
        simulation's lock, then :meth:`install_map` under it. Raises MapError if the map is too
        large for the grid caps (:mod:`cyborg.nav.map_limits`).
        """
        settings = self.settings
        world = MapGrid.from_map(arnl_map, settings.world_resolution, sim_obstacles=True)
        planner = planner or Planner(arnl_map)
        choice = choose_start(arnl_map, planner, start)  # an unknown name changes nothing
        clearance = world.clearance(world.walls)
        base = RobotBase(clearance, (world.origin_x, world.origin_y), world.resolution)
        laser = Laser(world.walls, (world.origin_x, world.origin_y), world.resolution,
                      settings.laser, seed=settings.seed, clearance=clearance)
        return PreparedMap(arnl_map, world, planner, base, laser, choice)

    def install_map(self, prepared: PreparedMap) -> None:
        """Switch to a map :meth:`prepare_map` built: quick, so it can hold the lock."""
        settings = self.settings
        self.map, self.world, self.planner = prepared.map, prepared.world, prepared.planner
        self.bounds = prepared.map.bounds()
        self.base, self.laser = prepared.base, prepared.laser
        self.base.others = self.others
        self.angles = settings.laser.angles()
        self.navigator = Navigator(prepared.planner, settings.navigator)
        self.docking = Docking(settings.dock)
        self.battery.charging = False
        self._teleop = self._target = None
        choice = prepared.start_choice
        self.start_choice: StartChoice = choice
        log.log(logging.WARNING if choice.invented else logging.INFO, "%s", choice.reason)
        self.base.place(choice.pose)
        self._sense()

    @property
    def pose(self) -> Pose2D:
        """The robot's pose now, in the map frame (m, rad)."""
        return self.base.pose

    @property
    def outline(self) -> np.ndarray:
        """The robot's outline where it stands (:attr:`RobotBase.outline`; read, never change)."""
        return self.base.outline

    def meet(self, others: tuple[np.ndarray, ...], points: np.ndarray | None = None,
             people: np.ndarray | None = None) -> None:
        """The other robots (and people) near this one: their outlines (K x 2 map coordinates).

        Until the next call the laser sees them and the drive cannot pass through them; the
        navigator and the motion check keep clear of ``points`` (N x 2, m: along their outlines
        and braking ways, :mod:`~cyborg.sim.bodies`; None keeps the last). The laser sees
        ``people`` too ((M, 3): x, y, radius; None keeps the last). No others: alone.
        """
        self.others = self.base.others = others
        if points is not None:
            self._points = points
        if people is not None:
            self.people = people

    @property
    def current_goal(self) -> Target | None:
        """The goal the robot is on its way to (docking: the dock), or None."""
        if self._target is None or self.navigator.state.finished:
            return None
        return self._target

    def way_ahead(self) -> np.ndarray:
        """The next (N, 2) points of its way, 2 ``obstacle_range`` on (a way winds); or none."""
        return self.navigator.way_ahead(self.pose, 2 * self.settings.navigator.obstacle_range)

    # ------------------------------------------------------------------ requests
    def resolve(self, goal: Pose2D | str, use_heading: bool | None = None) -> tuple[Pose2D, bool]:
        """A goal name or pose as ``(pose, use_heading)``; a name's kind decides the heading."""
        if isinstance(goal, str):
            item = self.map.goal(goal)
            heading = item.has_heading if use_heading is None else use_heading
            return Pose2D(item.x, item.y, item.theta), heading
        return goal, bool(use_heading)

    def go_to(self, goal: Pose2D | str, use_heading: bool | None = None) -> PlanResult:
        """Start driving to ``goal``; when docked, undock first (ARNL does the same)."""
        pose, heading = self.resolve(goal, use_heading)
        self._teleop = None
        comment = self.map.goal(goal).description if isinstance(goal, str) else ""
        self._target = Target(goal if isinstance(goal, str) else "", pose, heading, comment)
        if self.docking.state is not DockState.UNDOCKED:
            self._after_dock = (pose, heading)
            result = self.planner.plan(self.pose, pose, use_heading=heading)
            if result.found:
                self.undock()
                self.navigator.state = PathState.PLANNING_PATH
            else:
                self.navigator.state, self.navigator.message = PathState.FAILED_PLAN, result.reason
                self._after_dock = None
            return result
        return self.navigator.go_to(self.pose, pose, heading, self.time)

    def cancel(self) -> None:
        """Stop: abandon the goal (and a docking in progress)."""
        self._after_dock = None
        self.navigator.cancel()
        if self.docking.state is DockState.DOCKING:
            self.docking.enter(DockState.UNDOCKED, DockPhase.NONE, self.time)
            self.docking.message = "docking cancelled"

    def dock(self) -> bool:
        """Drive to the map's dock and dock; False (with ``docking.message``) without a dock."""
        if self.docking.state in (DockState.DOCKED, DockState.DOCKING):
            return True
        docks = self.map.docks()
        if not docks:
            self.docking.message = f"{self.map.source} has no Dock"
            return False
        item = docks[0]
        self._teleop = None
        self._target = Target(item.name, Pose2D(item.x, item.y, item.theta), True,
                              item.description)
        result = self.navigator.go_to(self.pose, self._target.pose, True, self.time)
        if not result.found:
            self.docking.message = f"cannot reach the dock: {result.reason}"
            return False
        self.docking.message = ""
        self.docking.enter(DockState.DOCKING, DockPhase.APPROACH, self.time)
        return True

    def undock(self) -> bool:
        """Start undocking if docked; whether the robot is undocking now."""
        if self.docking.state is not DockState.DOCKED:
            return self.docking.state is DockState.UNDOCKING
        self.battery.charging = False
        self.docking.enter(DockState.UNDOCKING, DockPhase.WAIT, self.time)
        return True

    # ------------------------------------------------------------------ by hand
    def teleop(self, speed: float, turn_rate: float) -> tuple[float, float]:
        """Drive by hand at ``speed`` (m/s) and ``turn_rate`` (rad/s) until told otherwise.

        Cancels any goal and docking (as :meth:`cancel`); a command that moves the robot
        takes it off the dock (charging ends). The command is clamped
        (:func:`~cyborg.sim.manual.limit_command`; ValueError when not finite), held until the
        next one or :meth:`end_teleop`, and checked every control period against the walls and
        the laser's returns: the robot slows and stops rather than touch them. Zero stops.
        Returns the clamped command.
        """
        command = limit_command(speed, turn_rate, self.base.limits)
        self.cancel()
        if command != (0.0, 0.0) and self.docking.state in (DockState.DOCKED,
                                                             DockState.UNDOCKING):
            self.battery.charging = False
            self.docking.enter(DockState.UNDOCKED, DockPhase.NONE, self.time)
            self.docking.message = "driven off the dock by hand"
        self._teleop = command
        return command

    @property
    def teleop_command(self) -> tuple[float, float] | None:
        """The command driving the robot by hand, or None when it is not driven by hand."""
        return self._teleop

    def end_teleop(self) -> None:
        """Stop driving by hand: the robot brakes to a standstill."""
        self._teleop = None

    def set_pose(self, pose: Pose2D) -> str | None:
        """Put the robot at ``pose`` at once, standing still; or say why not (None: done).

        Refused (nothing changes) when :func:`~cyborg.sim.manual.placement_problem` finds one.
        Otherwise any goal, docking and driving by hand end first, and the robot leaves the
        dock (charging ends).
        """
        self.base.others = self.others  # every robot it met, not only those it may touch now
        problem = placement_problem(pose, self.bounds, self.base, self.world)
        if problem is not None:
            return problem
        self.cancel()
        self._teleop = None
        if self.docking.state is not DockState.UNDOCKED:
            self.battery.charging = False
            self.docking.enter(DockState.UNDOCKED, DockPhase.NONE, self.time)
            self.docking.message = "moved off the dock"
        self.base.place(Pose2D(pose.x, pose.y, normalize_angle(pose.theta)))
        self._command = (0.0, 0.0)
        self._sense()
        return None

    # ------------------------------------------------------------------ time
    def step(self) -> None:
        """Advance one physics step."""
        dt = 1.0 / self.settings.physics_rate
        if self._steps % self.steps_per_sensor == 0:
            if self.crowd is not None:
                self.meet(*self.crowd.beside(self.planner, self.outline, self._period,
                                             self.laser.spec.range_max, self.base.speed,
                                             self.way_ahead))
            self._sense()
            self._command = self._decide()
        self._steps += 1
        self.base.command(*self._command, dt)
        self.battery.step(dt, self.base.speed)
        self.time = self._steps * dt

    def run(self, seconds: float) -> None:
        """Step through ``seconds`` of simulated time, rounded to whole physics steps."""
        for _ in range(round(seconds * self.settings.physics_rate)):
            self.step()

    def run_until(self, done: Callable[[], bool], timeout: float) -> bool:
        """Step until ``done()`` or ``timeout`` simulated seconds; whether it got done."""
        end = self.time + timeout
        while not done():
            if self.time >= end:
                return False
            self.step()
        return True

    @property
    def _period(self) -> float:
        return self.steps_per_sensor / self.settings.physics_rate

    def _motion(self) -> Motion:
        base, limits = self.base, self.base.limits
        return Motion(base.speed, base.turn_rate, limits.acceleration, limits.turn_acceleration,
                      1.0 / self.settings.physics_rate)

    def _sense(self) -> None:
        pose = self.base.pose
        self.ranges = self.laser.scan(pose.x, pose.y, pose.theta, self.others, self.people)
        self.hits = self.laser.points(pose.x, pose.y, pose.theta, self.ranges)
        self.scans += 1

    def _decide(self) -> tuple[float, float]:
        if self.docking.state is not DockState.UNDOCKED:
            return self._dock_step()
        if self._teleop is not None:
            return self._drive_by_hand(self._teleop)
        return self.navigator.update(self.time, self.base.pose, self.ranges, self.angles,
                                     self._obstacles(), self._motion(), self._period,
                                     self.laser.spec.mount_x)

    def _obstacles(self) -> np.ndarray:
        """What the robot knows is in its way: the laser's returns and the other robots."""
        return np.concatenate([self.hits, self._points]) if len(self._points) else self.hits

    def _drive_by_hand(self, wanted: tuple[float, float]) -> tuple[float, float]:
        """The hand-given command, or a gentler one if it would touch a wall or a return."""
        if wanted == (0.0, 0.0):
            return wanted
        base, pose = self.base, self.base.pose
        around = Surroundings(base.clearance, base.origin, base.resolution, self._obstacles())
        return safest_command(pose.x, pose.y, pose.theta, self._motion(), wanted, self._period,
                              base.footprint, around)

    def _dock_step(self) -> tuple[float, float]:
        docking, settings, now = self.docking, self.settings.dock, self.time
        pose = self.base.pose
        travelled = math.hypot(pose.x - docking.travelled_from[0],
                               pose.y - docking.travelled_from[1])
        if docking.phase is DockPhase.APPROACH:
            command = self.navigator.update(now, pose, self.ranges, self.angles,
                                            self._obstacles(), self._motion(), self._period,
                                            self.laser.spec.mount_x)
            state = self.navigator.state
            if state is PathState.REACHED_GOAL:
                docking.enter(DockState.DOCKING, DockPhase.DRIVE_IN, now, (pose.x, pose.y))
            elif state.finished:
                docking.message = f"docking failed: {self.navigator.message or state.value}"
                docking.enter(DockState.UNDOCKED, DockPhase.NONE, now)
            return command
        if docking.phase is DockPhase.DRIVE_IN:
            if travelled >= settings.depth or self.base.bumpers.front:
                docking.enter(DockState.DOCKING, DockPhase.POWER, now, docking.travelled_from)
                return 0.0, 0.0
            return settings.creep_speed, 0.0
        if docking.phase is DockPhase.POWER:
            if now - docking.phase_started >= settings.power_delay:
                self.battery.charging = True
                docking.docks += 1
                docking.enter(DockState.DOCKED, DockPhase.NONE, now)
            return 0.0, 0.0
        if docking.phase is DockPhase.WAIT:
            if now - docking.phase_started >= settings.undock_wait:
                docking.enter(DockState.UNDOCKING, DockPhase.BACK_OUT, now, (pose.x, pose.y))
            return 0.0, 0.0
        if docking.phase is DockPhase.BACK_OUT:
            if travelled >= settings.back_out or self.base.bumpers.rear:
                docking.enter(DockState.UNDOCKED, DockPhase.NONE, now)
                if self._after_dock is not None:
                    goal, heading = self._after_dock
                    self._after_dock = None
                    self.navigator.go_to(pose, goal, heading, now)
                return 0.0, 0.0
            return -settings.creep_speed, 0.0
        return 0.0, 0.0  # DOCKED
