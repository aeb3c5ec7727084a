"""The simulator as a component: its parameters, their defaults, and how it starts.

:func:`start` is the ``simulator`` kind of launch files (see :mod:`cyborg.bus.component`) and
what ``cyborg sim`` and ``cyborg up`` run. It simulates the Pioneer LX on an ARNL map and serves
it (:class:`~cyborg.sim.node.SimulatorNode`) from node :data:`NAME` under the robot's namespace
(:data:`NAMESPACE`, ``/cyborg``, unless told otherwise), with these bus parameters:

=============  ========================================================================
parameter      meaning (default)
=============  ========================================================================
``map``        the ARNL .map file (required; read-only)
``start``      goal or dock to start at (the map's home, else its dock; read-only)
``speed``      simulated seconds per wall-clock second (:data:`SPEED`, 1: real time;
               0: as fast as possible); settable while it runs
``battery``    the charge at the start, percent (:data:`BATTERY`, full; read-only)
``robots``     how many robots (:data:`ROBOTS`, 1; read-only); see below
``battery_``   with several robots: percent each next robot's battery starts fuller than
``step``       the one before (up to full; 0: all alike; read-only)
``avoid_``     whether the navigator plans around the tracker's ``objects`` (true;
``objects``    read-only; :mod:`cyborg.sim.object_feed`)
``obstacle_``  the labels it plans around (``["person"]``; an empty string alone: every
``labels``     label; read-only)
=============  ========================================================================

and those of the people walking on the map and the robots' simulated cameras (``people``,
``people_seed``, ``camera``, ``camera_image``; :mod:`cyborg.sim.people_and_camera`): with
``camera`` true each robot's camera publishes detections as the detector does, under the
robot's detector namespace (``/cyborg/detector``), and while people walk their true poses are
on ``sim/people`` under the (first) robot's namespace.

With ``robots`` N > 1 it simulates a fleet on the map (:mod:`cyborg.sim.fleet`): one loop, one
``/clock``, and a node :data:`NAME` per robot under ``<namespace>/robot1`` …
``<namespace>/robotN`` (:func:`cyborg.interfaces.robot.fleet_namespaces`), each with these
parameters (``speed`` set on any of them paces the whole fleet). ``start`` places the first
robot, the others start near it. Only the first follows the absolute ``/initialpose``; each
robot's frames carry its name (``robot1/base_link``, ``robot1/laser``), see
:mod:`cyborg.sim.node`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any, NamedTuple

from cyborg.bus import Context, Node
from cyborg.bus.component import NodeSpec
from cyborg.interfaces import robot
from cyborg.nav.arnl_map import MapError, read_map
from cyborg.sim.battery import Battery
from cyborg.sim.fleet import MAX_ROBOTS, Fleet, robot_loops
from cyborg.sim.loop import REAL_TIME, PacedLoop, SimulationLoop
from cyborg.sim.node import SimulatorNode
from cyborg.sim.object_feed import follow_objects
from cyborg.sim.people_and_camera import (
    declare_extras,
    make_crowd,
    publish_people,
    start_cameras,
)
from cyborg.sim.simulator import Simulator

NAME = "arnl"
"""The simulator's node name unless told otherwise (rosarnl's, as in 2018)."""
NAMESPACE = robot.NAMESPACE
"""The robot's namespace unless told otherwise (``/cyborg``)."""
SPEED = REAL_TIME
"""Simulated seconds per wall-clock second unless told otherwise."""
BATTERY = Battery.charge_percent
"""The battery's charge at the start unless told otherwise, percent: full."""
ROBOTS = 1
"""How many robots unless told otherwise."""


class RunningSimulator:
    """A started simulator: its node, its loop, the map it runs on, its camera's node."""

    def __init__(self, node: Node, loop: SimulationLoop, map_path: Path,
                 cameras: Sequence[Node] = ()) -> None:
        self.node, self.loop, self.map_path = node, loop, map_path
        self.cameras = list(cameras)

    def describe(self) -> str:
        """The map, the pace, and where the robot's interface is."""
        speed = self.loop.speed
        pace = "as fast as possible" if math.isinf(speed) else f"{speed:g}x real time"
        crowd = self.loop.simulator.crowd
        people = f"; {len(crowd)} people walking" if crowd is not None else ""
        camera = "; a simulated camera under " + ", ".join(
            node.namespace for node in self.cameras) if self.cameras else ""
        return (f"simulator    {self.node.fq_name}: {self.map_path.name} at {pace}; "
                f"ARNL-like interface under {self.node.namespace}, /clock{people}{camera}")

    def stop(self) -> None:
        """Stops the simulation and leaves the bus."""
        self.loop.stop()
        for node in [*self.cameras, self.node]:
            node.destroy()


def start(context: Context, spec: NodeSpec) -> RunningSimulator | RunningFleet:
    """Starts the simulator from ``spec``; a map that cannot be read refuses it.

    With a ``robots`` parameter above 1 it is a fleet (see the module doc).
    """
    count = spec.parameters.get("robots", ROBOTS)
    if isinstance(count, bool) or not isinstance(count, int) or not 1 <= count <= MAX_ROBOTS:
        raise spec.error(f"parameter `robots` must be a whole number from 1 to {MAX_ROBOTS}, "
                         f"not {count!r}")
    if count > 1:
        return _start_fleet(context, spec, count)
    node = Node(spec.name, spec.namespace, context=context, parameters=spec.parameters)
    cameras: list[Node] = []
    try:
        settings, extras = _declare(node, spec), declare_extras(node, spec)
        try:
            arnl_map = read_map(settings.map_path)
            simulator = Simulator(arnl_map, start=settings.start or None,
                                  battery=Battery(charge_percent=settings.charge))
            pose = simulator.pose
            simulator.crowd = make_crowd(arnl_map, simulator.planner, extras, [(pose.x, pose.y)])
            loop = SimulationLoop(simulator, settings.speed)
            _pace(node, loop)
            SimulatorNode(node, loop)
            cameras = start_cameras(context, [(node, loop)], simulator.crowd, extras)
        except (MapError, KeyError, ValueError) as exc:
            raise spec.error(str(exc).strip("\"'")) from exc
        follow_objects(node, loop, spec)
        publish_people(node, loop, simulator.crowd)
        loop.start()
    except BaseException:
        for each in [*cameras, node]:
            each.destroy()
        raise
    return RunningSimulator(node, loop, settings.map_path, cameras)


class _Settings(NamedTuple):
    map_path: Path
    start: str
    speed: float
    charge: float
    step: float


def _declare(node: Node, spec: NodeSpec) -> _Settings:
    """Declares the simulator's parameters on ``node``; refuses a spec without a map."""
    params = node.parameters
    map_value = params.declare("map", "", "ARNL .map file", read_only=True)
    if not map_value:
        raise spec.error("the simulator needs a `map` parameter (an ARNL .map file)")
    start = params.declare("start", "", "goal or dock to start at", read_only=True)
    speed = params.declare("speed", SPEED, "simulated seconds per second (0: flat out)")
    charge = params.declare("battery", BATTERY, "battery charge at the start, percent",
                            read_only=True, limits=(0.0, 100.0))
    step = 0.0
    if "robots" in spec.parameters:
        params.declare("robots", ROBOTS, "how many robots", read_only=True)
        step = float(params.declare("battery_step", 0.0, "percent each next robot's battery "
                                    "starts fuller", read_only=True, limits=(0.0, 100.0)))
    return _Settings(spec.path(str(map_value)), str(start), float(speed), float(charge), step)


def _pace(node: Node, loop: PacedLoop[Any]) -> None:
    """Lets ``node``'s ``speed`` parameter pace ``loop`` while it runs."""
    def check(changes: dict[str, Any]) -> None:
        if "speed" in changes and float(changes["speed"]) < 0:
            raise ValueError("speed must be positive, or 0 for as fast as possible")

    def change(changes: dict[str, Any]) -> None:
        if "speed" in changes:
            loop.speed = float(changes["speed"])
    node.parameters.on_set(check)
    node.parameters.on_change(change)


class RunningFleet:
    """A started fleet: its robots' nodes, its loop, the fleet and the map it runs on."""

    def __init__(self, nodes: list[Node], loop: PacedLoop[Fleet], map_path: Path,
                 cameras: Sequence[Node] = ()) -> None:
        self.nodes, self.loop, self.map_path = nodes, loop, map_path
        self.fleet = loop.simulator
        self.cameras = list(cameras)

    def describe(self) -> str:
        """The map, the pace, and where each robot's interface is."""
        speed = self.loop.speed
        pace = "as fast as possible" if math.isinf(speed) else f"{speed:g}x real time"
        names = ", ".join(node.namespace for node in self.nodes)
        crowd = self.fleet.crowd
        people = f"; {len(crowd)} people walking" if crowd is not None else ""
        camera = "; simulated cameras" if self.cameras else ""
        return (f"simulator    {len(self.nodes)} robots on {self.map_path.name} at {pace}: "
                f"ARNL-like interfaces under {names}; /clock{people}{camera}")

    def stop(self) -> None:
        """Stops the simulation and leaves the bus."""
        self.loop.stop()
        for node in [*self.cameras, *self.nodes]:
            node.destroy()


def _start_fleet(context: Context, spec: NodeSpec, count: int) -> RunningFleet:
    nodes: list[Node] = []
    cameras: list[Node] = []
    try:
        for namespace in robot.fleet_namespaces(spec.namespace, count):
            nodes.append(Node(spec.name, namespace, context=context,
                              parameters=spec.parameters))
        settings = [_declare(node, spec) for node in nodes][-1]  # the same for each
        extras = [declare_extras(node, spec) for node in nodes][-1]
        try:
            arnl_map = read_map(settings.map_path)
            fleet = Fleet(arnl_map, count, settings.start or None,
                          charges=[min(settings.charge + index * settings.step, 100.0)
                                   for index in range(count)])
            planner = fleet.simulators[0].planner
            fleet.crowd = make_crowd(arnl_map, planner, extras, [
                (sim.pose.x, sim.pose.y) for sim in fleet.simulators])
            loop = PacedLoop(fleet, settings.speed)
            shares = robot_loops(loop)
            for index, (node, share) in enumerate(zip(nodes, shares, strict=True)):
                _pace(node, loop)
                SimulatorNode(node, share, initial_pose=index == 0, publishes_clock=index == 0,
                              frame_prefix=node.namespace.strip("/") + "/")
            cameras = start_cameras(context, list(zip(nodes, shares, strict=True)), fleet.crowd,
                                    extras)
        except (MapError, KeyError, ValueError) as exc:
            raise spec.error(str(exc).strip("\"'")) from exc
        for node, share in zip(nodes, shares, strict=True):
            follow_objects(node, share, spec)
        publish_people(nodes[0], shares[0], fleet.crowd)
        loop.start()
    except BaseException:
        for node in [*cameras, *nodes]:
            node.destroy()
        raise
    return RunningFleet(nodes, loop, settings.map_path, cameras)
