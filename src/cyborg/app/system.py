"""The running system: a launch description's components, followed on the terminal.

They are started on the bus, followed, and stopped in order. ``cyborg up``, ``launch``,
``monitor`` and ``bt serve`` each build a :class:`~cyborg.app.launch.LaunchDescription` and
hand it to :func:`run_system`.
"""

from __future__ import annotations

import argparse
import logging
import sys
from collections.abc import Iterator, Sequence
from contextlib import contextmanager

from cyborg.app.bus_options import bus_context
from cyborg.app.errors import CommandError
from cyborg.app.goal_check import unknown_goals
from cyborg.app.launch import Launch, LaunchDescription, end_if_stuck
from cyborg.app.status_line import StatusLine
from cyborg.app.terminal import NamesRobot
from cyborg.bus import SimClock
from cyborg.bus.component import LaunchError
from cyborg.bus.config import CONNECT_ENV, BusConfig
from cyborg.modes import ModeMachine
from cyborg.runner.component import RunningTree
from cyborg.sim import component as sim


def run_system(description: LaunchDescription, args: argparse.Namespace, *, title: str,
               process: str = "main", parent: int | None = None,
               notes: Sequence[str] = ()) -> int:
    """Runs ``process``'s part of ``description`` until it is stopped; returns the exit code.

    Starts ``process``'s components (and, for ``main``, the other processes as children),
    prints ``notes`` and what runs, follows the tree, and stops everything in order
    (:meth:`Launch.stop`) on Ctrl-C, after ``--duration``, or when ``parent`` (a child's
    launch) has gone.
    """
    context, where = bus_context(description.connect, description.listen)
    launch = Launch(description, context)
    status_line: StatusLine | None = None
    code = 0
    try:
        children = [name for name in description.processes() if name != "main"] \
            if process == "main" else []
        connect = description.connect[0] if description.connect else description.listen
        launch.start(process, children=children, connect=connect)
        unknown = unknown_goals(launch)
        if unknown:  # stopped (below) before it runs long on the wrong map
            raise CommandError("\n".join(unknown))
        stops = "Ctrl-C stops everything" if parent is None else "stops with its launch"
        print(f"{title}: bus {where}; {stops}", flush=True)
        if connect and connect not in BusConfig.from_environment().connect:
            print(f"  other shells  export {CONNECT_ENV}={connect}  (or --connect {connect}): "
                  "commands join another bus by default", flush=True)
        for line in [*notes, *launch.describe()]:
            print(f"  {line}", flush=True)
        status_line = _follow_tree(launch)
        with _robots_named(launch):
            code = launch.wait(args.duration, parent=parent)
    except LaunchError as exc:
        raise CommandError(str(exc)) from exc
    finally:
        end_if_stuck(launch)
        launch.stop()
        context.close()
        if status_line is not None:  # ends a live line: what follows starts on its own
            status_line.finish(interrupted=code == 130 or sys.exc_info()[0] is KeyboardInterrupt)
    if code == 130:
        print(f"{title}: stopped", file=sys.stderr)
    return code


def _follow_tree(launch: Launch) -> StatusLine | None:
    """Prints a live status line for the first tree runner of this process.

    Of a mode file, the line follows the tree of the mode that ticked and names the mode first.
    On simulated time it shows the pace reached against the simulator's ``speed``, and warns
    once when that falls behind (:class:`StatusLine`).
    """
    for item in launch.running:
        if isinstance(item, RunningTree):
            runner = item.runner
            modes = isinstance(runner.ticked, ModeMachine)
            speed = _simulator_speed(launch.description) \
                if isinstance(runner.clock, SimClock) else None
            line = StatusLine(runner.tree, sys.stdout, tree_of=runner.tree_of,
                              mode_of=runner.mode_of if modes else None, speed=speed)
            line.attach()
            item.runner.runner.add_listener(line.update)
            return line
    return None


def _simulator_speed(description: LaunchDescription) -> float | None:
    """The pace the launch's simulator was asked for, if it starts one."""
    for spec in description.nodes:
        if spec.kind == "simulator":
            return float(spec.parameters.get("speed", sim.SPEED))
    return None


@contextmanager
def _robots_named(launch: Launch) -> Iterator[None]:
    """While inside, a fleet's log records name their robot (:class:`NamesRobot`)."""
    namespaces = [item.runner.node.parameters["robot_namespace"] for item in launch.running
                  if isinstance(item, RunningTree)]
    handlers = logging.getLogger().handlers
    naming = NamesRobot(namespaces)
    if len(namespaces) > 1:
        for handler in handlers:
            handler.addFilter(naming)
    try:
        yield
    finally:
        for handler in handlers:
            handler.removeFilter(naming)
