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
=============  ========================================================================
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from cyborg.bus import Context, Node
from cyborg.bus.component import NodeSpec
from cyborg.interfaces import robot
from cyborg.nav.arnl_map import MapError, read_map
from cyborg.sim.battery import Battery
from cyborg.sim.loop import REAL_TIME, SimulationLoop
from cyborg.sim.node import SimulatorNode
from cyborg.sim.simulator import Simulator

NAME = "arnl"
"""The simulator's node name unless told otherwise (rosarnl's, as in 2018)."""
NAMESPACE = robot.NAMESPACE
"""The robot's namespace unless told otherwise (``/cyborg``)."""
SPEED = REAL_TIME
"""Simulated seconds per wall-clock second unless told otherwise."""
BATTERY = Battery.charge_percent
"""The battery's charge at the start unless told otherwise, percent: full."""


class RunningSimulator:
    """A started simulator: its node, its loop and the map it runs on."""

    def __init__(self, node: Node, loop: SimulationLoop, map_path: Path) -> None:
        self.node, self.loop, self.map_path = node, loop, map_path

    def describe(self) -> str:
        """The map, the pace, and where the robot's interface is."""
        speed = self.loop.speed
        pace = "as fast as possible" if math.isinf(speed) else f"{speed:g}x real time"
        return (f"simulator    {self.node.fq_name}: {self.map_path.name} at {pace}; "
                f"ARNL-like interface under {self.node.namespace}, /clock")

    def stop(self) -> None:
        """Stops the simulation and leaves the bus."""
        self.loop.stop()
        self.node.destroy()


def start(context: Context, spec: NodeSpec) -> RunningSimulator:
    """Starts the simulator from ``spec``; a map that cannot be read refuses it."""
    node = Node(spec.name, spec.namespace, context=context, parameters=spec.parameters)
    try:
        params = node.parameters
        map_value = params.declare("map", "", "ARNL .map file", read_only=True)
        if not map_value:
            raise spec.error("the simulator needs a `map` parameter (an ARNL .map file)")
        start = params.declare("start", "", "goal or dock to start at", read_only=True)
        speed = params.declare("speed", SPEED, "simulated seconds per second (0: flat out)")
        charge = params.declare("battery", BATTERY, "battery charge at the start, percent",
                                read_only=True, limits=(0.0, 100.0))
        map_path = spec.path(str(map_value))
        try:
            arnl_map = read_map(map_path)
            simulator = Simulator(arnl_map, start=start or None,
                                  battery=Battery(charge_percent=float(charge)))
            loop = SimulationLoop(simulator, float(speed))
        except (MapError, KeyError, ValueError) as exc:
            raise spec.error(str(exc).strip("\"'")) from exc

        def check(changes: dict[str, Any]) -> None:
            if "speed" in changes and float(changes["speed"]) < 0:
                raise ValueError("speed must be positive, or 0 for as fast as possible")

        def change(changes: dict[str, Any]) -> None:
            if "speed" in changes:
                loop.speed = float(changes["speed"])
        params.on_set(check)
        params.on_change(change)
        SimulatorNode(node, loop)
        loop.start()
    except BaseException:
        node.destroy()
        raise
    return RunningSimulator(node, loop, map_path)
