"""The tree runner as a component: its parameters, their defaults, and how it starts.

:func:`start` is the ``tree_runner`` kind of launch files (see :mod:`cyborg.bus.component`).
It ticks a behavior3editor tree as :class:`~cyborg.runner.tree_runner.TreeRunnerNode` under the
spec's namespace (:data:`NAMESPACE`, ``/cyborg/bt``, unless told otherwise) with these
read-only bus parameters:

=======================  ============================================================
parameter                meaning (default)
=======================  ============================================================
``tree_file``            the behavior3editor export to run, or a mode file (``*.toml``,
                         docs/modes.md) whose machine to run (required)
``tree``                 tree id or title (the file's selected tree)
``rate``                 ticks per second (:data:`RATE`, 10)
``use_sim_time``         tick on simulated time from ``/clock`` (false)
``clock_jump_limit``     seconds ``/clock`` may jump before it is reported (10)
``clock_stall_timeout``  wall seconds without ``/clock`` advancing before it is said (5)
``robot_namespace``      the robot's namespace (:data:`ROBOT_NAMESPACE`, ``/cyborg``)
``enabled``              tick from the start (true)
``nodes``                modules of node classes to import first (none)
=======================  ============================================================

The robot the tree's nodes act on is not the runner's to choose: the runner knows only
:class:`~cyborg.robot.protocol.Robot`. Whoever wires the system passes a :data:`RobotFactory`
(``cyborg.app`` gives the robot on the bus, :class:`~cyborg.robot.settling_robot.
SettlingBusRobot`); without one the tree runs without a robot, for trees that need none.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Protocol

from cyborg.bt import Clock, MonotonicClock, TreeLoadError, default_registry
from cyborg.bt.tick_loop import DEFAULT_RATE
from cyborg.bus import Context, Node, SimClock
from cyborg.bus.clock import JUMP_LIMIT, STALL_TIMEOUT
from cyborg.bus.component import NodeSpec
from cyborg.interfaces import robot, tree_runner
from cyborg.robot.protocol import Robot
from cyborg.runner.ticked import describe
from cyborg.runner.tree_runner import TreeRunnerNode

NAME = "tree_runner"
"""The runner's node name unless told otherwise."""
NAMESPACE = tree_runner.NAMESPACE
"""The runner's namespace unless told otherwise (``/cyborg/bt``)."""
RATE = DEFAULT_RATE
"""Ticks per second unless told otherwise."""
ROBOT_NAMESPACE = robot.NAMESPACE
"""The namespace of the robot the tree acts on unless told otherwise (``/cyborg``)."""


class SettlingRobot(Robot, Protocol):
    """A robot whose moves a stopping runner can wait for."""

    def settle(self, timeout: float = 5.0) -> bool:
        """Waits (at most ``timeout`` wall seconds) until every move has ended; True if all did."""
        ...


RobotFactory = Callable[[Node, str], SettlingRobot]
"""Makes the tree's robot from a node of its own and the robot's namespace."""


class RunningTree:
    """A started tree runner: its node, and the robot's node and robot, if it has one."""

    def __init__(self, runner: TreeRunnerNode, robot_node: Node | None = None,
                 robot: SettlingRobot | None = None) -> None:
        self.runner, self.robot_node, self.robot = runner, robot_node, robot

    def describe(self) -> str:
        """One line: the tree, its file, rate and clock, and where its topics are.

        Of a mode file it names the modes and the current one with its tree.
        """
        node = self.runner.node
        clock = "simulated time (/clock)" if isinstance(self.runner.clock, SimClock) \
            else "wall-clock time"
        return (f"tree runner  {node.fq_name}: {describe(self.runner.ticked)} from "
                f"{self.runner.path.name} at {self.runner.runner.rate_hz:g} Hz on {clock}; "
                f"topics {node.namespace}/behavior_tree, .../status; enable: "
                f"{node.namespace}/enable")

    def stop(self) -> None:
        """Halts the tree, waits until the robot has ended its goals, then leaves the bus.

        Halting makes a running MoveTo cancel its goal; the robot's node stays on the bus until
        the robot has answered (at most 5 s), so the robot stops.
        """
        self.runner.stop()
        if self.robot is not None:
            self.robot.settle()
        self.runner.destroy()
        if self.robot_node is not None:
            self.robot_node.destroy()


def start(context: Context, spec: NodeSpec, *,
          robot: RobotFactory | None = None) -> RunningTree:
    """Starts a tree runner from ``spec``; the tree acts on what ``robot`` makes, if given.

    The robot gets a node of its own, ``<name>_robot`` in the runner's namespace. A tree file
    with errors is refused with every problem, before anything ticks.
    """
    node = Node(spec.name, spec.namespace, context=context, parameters=spec.parameters)
    robot_node: Node | None = None
    try:
        params = node.parameters
        tree_file = params.declare("tree_file", "", "behavior3editor export or mode file",
                                   read_only=True)
        if not tree_file:
            raise spec.error("the tree runner needs a `tree_file` parameter")
        choice = params.declare("tree", "", "tree id or title (default: selectedTree)",
                                read_only=True)
        rate = params.declare("rate", RATE, "ticks per second", read_only=True)
        sim_time = params.declare("use_sim_time", False, "tick on /clock", read_only=True)
        jump_limit = params.declare(
            "clock_jump_limit", JUMP_LIMIT, "seconds /clock may jump before it is reported "
            "(and, forward from a publisher not in the graph, refused)", read_only=True,
            limits=(1e-3, 1e9))
        stall_timeout = params.declare(
            "clock_stall_timeout", STALL_TIMEOUT, "wall seconds without /clock advancing "
            "before the runner says so", read_only=True, limits=(1e-3, 1e9))
        robot_ns = params.declare("robot_namespace", ROBOT_NAMESPACE, "the robot's namespace",
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
        the_robot: SettlingRobot | None = None
        if robot is not None:
            robot_node = Node(f"{spec.name}_robot", spec.namespace, context=context)
            the_robot = robot(robot_node, str(robot_ns))
        try:
            runner = TreeRunnerNode(node, spec.path(str(tree_file)), tree=choice or None,
                                    rate_hz=float(rate), clock=clock, robot=the_robot,
                                    registry=registry, enabled=bool(enabled))
        except TreeLoadError as exc:
            problems = "\n".join(f"  {problem}" for problem in exc.problems)
            kind = "mode" if str(tree_file).endswith(".toml") else "tree"
            raise spec.error(f"the {kind} file has errors:\n{problems}") from exc
        runner.start()
    except BaseException:
        node.destroy()
        if robot_node is not None:
            robot_node.destroy()
        raise
    return RunningTree(runner, robot_node, the_robot)
