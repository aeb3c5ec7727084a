"""The kinds of node a launch file can start, and how each one starts.

Every kind is a function ``start(context, spec) -> Running``: it creates its bus node(s) in the
given context from the spec's name, namespace and parameters, starts working, and returns a
handle that can describe itself and stop. Parameters become the node's bus parameters, so
``cyborg param list`` shows them and the changeable ones (the simulator's ``speed``) can be set
at runtime.

==============  ================================================================================
kind            parameters (default)
==============  ================================================================================
``simulator``   ``map`` (required), ``start`` (the map's home or dock), ``speed`` (1.0; 0 = as
                fast as possible), ``battery`` (start charge, 100 %)
``tree_runner`` ``tree_file`` (required), ``tree`` (the file's selected tree), ``rate`` (10 Hz),
                ``use_sim_time`` (false), ``robot_namespace`` (/cyborg), ``enabled`` (true),
                ``nodes`` (modules of node classes to import, [])
``monitor``     ``trees`` (tree runner namespaces, ["/cyborg/bt"]), ``port`` (8080; 0 = any
                free port), ``host`` (127.0.0.1; 0.0.0.0 = every interface),
                ``allow_hosts`` (more names the page may be opened as), ``token_file``
                (control from other machines; default ``$CYBORG_MONITOR_TOKEN``); ``token``
                (the token itself) is read but never made a bus parameter
``camera``,     see :mod:`cyborg.app.vision_launchables`
``detector``
==============  ================================================================================

A user's own kind is given as ``"package.module:function"`` with the same signature.
"""

from __future__ import annotations

import importlib
import math
import time
from pathlib import Path
from typing import Any

from cyborg.app.node_spec import LaunchError, NodeSpec, Running, Starter
from cyborg.app.vision_launchables import start_camera, start_detector
from cyborg.bt import Clock, MonotonicClock, TreeLoadError, default_registry

__all__ = ["KINDS", "LaunchError", "NodeSpec", "Running", "RunningMonitor", "RunningSimulator",
           "RunningTree", "SettlingRobot", "Starter", "starter_for"]
from cyborg.bus import Context, Node, SimClock
from cyborg.bus.clock import JUMP_LIMIT, STALL_TIMEOUT
from cyborg.monitor import (
    DEFAULT_HOST,
    DEFAULT_PORT,
    Monitor,
    MonitorError,
    TokenError,
    read_token,
)
from cyborg.nav.arnl_map import MapError, read_map
from cyborg.robot.bus_robot import BusMove, BusRobot
from cyborg.runner.tree_runner import TreeRunnerNode
from cyborg.sim.battery import Battery
from cyborg.sim.loop import SimulationLoop
from cyborg.sim.node import SimulatorNode
from cyborg.sim.simulator import Simulator


# ---------------------------------------------------------------------------------- simulator
class RunningSimulator:
    def __init__(self, node: Node, loop: SimulationLoop, map_path: Path) -> None:
        self.node, self.loop, self.map_path = node, loop, map_path

    def describe(self) -> str:
        speed = self.loop.speed
        pace = "as fast as possible" if math.isinf(speed) else f"{speed:g}x real time"
        return (f"simulator    {self.node.fq_name}: {self.map_path.name} at {pace}; "
                f"ARNL-like interface under {self.node.namespace}, /clock")

    def stop(self) -> None:
        self.loop.stop()
        self.node.destroy()


def start_simulator(context: Context, spec: NodeSpec) -> RunningSimulator:
    node = Node(spec.name, spec.namespace, context=context, parameters=spec.parameters)
    try:
        params = node.parameters
        map_value = params.declare("map", "", "ARNL .map file", read_only=True)
        if not map_value:
            raise spec.error("the simulator needs a `map` parameter (an ARNL .map file)")
        start = params.declare("start", "", "goal or dock to start at", read_only=True)
        speed = params.declare("speed", 1.0, "simulated seconds per second (0: flat out)")
        charge = params.declare("battery", 100.0, "battery charge at the start, percent",
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


# ---------------------------------------------------------------------------------- tree runner
class SettlingRobot(BusRobot):
    """The tree runner's robot, which remembers the moves it started.

    Halting a MoveTo only *sends* the cancel (the tick must not block), so a runner that
    destroyed its bus nodes right after halting would withdraw the cancel's client before the
    robot answered, and the robot would drive on. :meth:`settle` waits until every move has
    ended: stopping a tree runner calls it between the halt and the nodes' end."""

    def __init__(self, node: Node, namespace: str) -> None:
        super().__init__(node, namespace)
        self._moves: list[BusMove] = []

    def move_to(self, goal: str) -> BusMove:
        move = super().move_to(goal)
        self._moves = [*(earlier for earlier in self._moves if not earlier.done), move]
        return move

    def settle(self, timeout: float = 5.0) -> bool:
        """Wait (wall time, at most ``timeout``) until every move has ended; True if all did."""
        deadline = time.monotonic() + timeout
        while any(not move.done for move in self._moves):
            if time.monotonic() > deadline:
                return False
            time.sleep(0.01)
        return True


class RunningTree:
    def __init__(self, runner: TreeRunnerNode, robot_node: Node,
                 robot: SettlingRobot | None = None) -> None:
        self.runner, self.robot_node, self.robot = runner, robot_node, robot

    def describe(self) -> str:
        tree, node = self.runner.tree, self.runner.node
        clock = "simulated time (/clock)" if isinstance(self.runner.clock, SimClock) \
            else "wall-clock time"
        return (f"tree runner  {node.fq_name}: {tree.title!r} ({len(tree)} nodes) from "
                f"{self.runner.path.name} at {self.runner.runner.rate_hz:g} Hz on {clock}; "
                f"topics {node.namespace}/behavior_tree, .../status; enable: "
                f"{node.namespace}/enable")

    def stop(self) -> None:
        """Halt the tree (a running MoveTo cancels its goal), wait until the robot has ended
        the goals, then leave the bus."""
        self.runner.stop()
        if self.robot is not None:
            self.robot.settle()
        self.runner.destroy()
        self.robot_node.destroy()


def start_tree_runner(context: Context, spec: NodeSpec) -> RunningTree:
    node = Node(spec.name, spec.namespace, context=context, parameters=spec.parameters)
    robot_node: Node | None = None
    try:
        params = node.parameters
        tree_file = params.declare("tree_file", "", "behavior3editor export", read_only=True)
        if not tree_file:
            raise spec.error("the tree runner needs a `tree_file` parameter")
        choice = params.declare("tree", "", "tree id or title (default: selectedTree)",
                                read_only=True)
        rate = params.declare("rate", 10.0, "ticks per second", read_only=True)
        sim_time = params.declare("use_sim_time", False, "tick on /clock", read_only=True)
        jump_limit = params.declare(
            "clock_jump_limit", JUMP_LIMIT, "seconds /clock may jump before it is reported "
            "(and, forward from a publisher not in the graph, refused)", read_only=True,
            limits=(1e-3, 1e9))
        stall_timeout = params.declare(
            "clock_stall_timeout", STALL_TIMEOUT, "wall seconds without /clock advancing "
            "before the runner says so", read_only=True, limits=(1e-3, 1e9))
        robot_ns = params.declare("robot_namespace", "/cyborg", "the robot's namespace",
                                  read_only=True)
        enabled = params.declare("enabled", True, "tick from the start", read_only=True)
        modules = params.declare("nodes", [""], "modules of node classes to import",
                                 read_only=True)
        registry = default_registry()
        try:
            registry.import_modules([module for module in modules if module])
        except ImportError as exc:
            raise spec.error(str(exc)) from exc
        clock: Clock = SimClock(node, jump_limit=float(jump_limit),
                                stall_timeout=float(stall_timeout)) if sim_time \
            else MonotonicClock()
        robot_node = Node(f"{spec.name}_robot", spec.namespace, context=context)
        robot = SettlingRobot(robot_node, str(robot_ns))
        try:
            runner = TreeRunnerNode(node, spec.path(str(tree_file)), tree=choice or None,
                                    rate_hz=float(rate), clock=clock, robot=robot,
                                    registry=registry, enabled=bool(enabled))
        except TreeLoadError as exc:
            problems = "\n".join(f"  {problem}" for problem in exc.problems)
            raise spec.error(f"the tree file has errors:\n{problems}") from exc
        runner.start()
    except BaseException:
        node.destroy()
        if robot_node is not None:
            robot_node.destroy()
        raise
    return RunningTree(runner, robot_node, robot)


# ---------------------------------------------------------------------------------- monitor
class RunningMonitor:
    def __init__(self, monitor: Monitor) -> None:
        self.monitor = monitor

    def describe(self) -> str:
        urls = self.monitor.urls()
        others = (f" (from other machines: {', '.join(urls[1:])})" if urls[1:] else
                  " (this machine only)" if self.monitor.on_loopback else "")
        line = (f"monitor      {self.monitor.node.fq_name}: open {urls[0]}{others}; trees "
                f"{', '.join(sorted(self.monitor.hub.sources))}")
        exposure = self.monitor.exposure()
        return f"{line}\n               {exposure}" if exposure else line

    def stop(self) -> None:
        self.monitor.stop()


def start_monitor(context: Context, spec: NodeSpec) -> RunningMonitor:
    # the token is a secret: read here, never declared (`cyborg param get` would show it)
    parameters = {name: value for name, value in spec.parameters.items() if name != "token"}
    node = Node(spec.name, spec.namespace, context=context, parameters=parameters)
    try:
        params = node.parameters
        trees = params.declare("trees", ["/cyborg/bt"], "tree runner namespaces to follow",
                               read_only=True)
        port = params.declare("port", DEFAULT_PORT, "web server port (0: any free port)",
                              read_only=True)
        host = params.declare("host", DEFAULT_HOST, "address to listen on (0.0.0.0: every "
                              "interface)", read_only=True)
        allow_hosts = params.declare("allow_hosts", ["localhost"], "names the page may be "
                                     "opened as, beside this machine's", read_only=True)
        token_file = params.declare("token_file", "", "file holding the token for control "
                                    "from other machines", read_only=True)
        try:
            token = read_token(str(spec.parameters.get("token") or "") or None,
                               spec.path(str(token_file)) if token_file else None)
            monitor = Monitor(node, namespaces=[str(tree) for tree in trees], host=str(host),
                              port=int(port), token=token,
                              allow_hosts=[str(name) for name in allow_hosts])
        except TokenError as exc:
            raise spec.error(str(exc)) from None
        except ValueError as exc:
            raise spec.error(f"trees: {exc}") from None
        try:
            monitor.start()
        except MonitorError as exc:
            raise spec.error(str(exc)) from exc
    except BaseException:
        node.destroy()
        raise
    return RunningMonitor(monitor)


KINDS: dict[str, Starter] = {"simulator": start_simulator, "tree_runner": start_tree_runner,
                             "monitor": start_monitor, "camera": start_camera,
                             "detector": start_detector}


def starter_for(spec: NodeSpec) -> Starter:
    """The start function of ``spec.kind``: a known kind or ``module:function``."""
    if spec.kind in KINDS:
        return KINDS[spec.kind]
    module_name, _, function = spec.kind.partition(":")
    if not function:
        raise spec.error(f"unknown kind {spec.kind!r}; known: {', '.join(sorted(KINDS))}, "
                         "or 'package.module:function'")
    try:
        module = importlib.import_module(module_name)
        starter: Starter = getattr(module, function)
    except (ImportError, AttributeError) as exc:
        raise spec.error(f"cannot load kind {spec.kind!r}: {type(exc).__name__}: {exc}") from exc
    return starter
