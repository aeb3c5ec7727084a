"""``cyborg sim`` (the simulated robot as a bus node) and ``cyborg nav`` (maps offline).

::

    cyborg sim --map AMROffice.map [--speed 10] [--start Dock] [--namespace /cyborg]
    cyborg sim --map AMROffice.map --speed 0 --duration 3600   # an hour, flat out
    cyborg sim --map AMROffice.map --robots 3 --namespace /    # /robot1, /robot2, /robot3
    cyborg nav goals AMROffice.map
    cyborg nav plan AMROffice.map Dock room1        # names, or x,y[,heading] in metres/degrees

``cyborg sim`` runs the simulator component (:mod:`cyborg.sim.component`), with its defaults.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path
from typing import Any

from cyborg.app.bus_options import DEFAULT_ROUTER, bus_context
from cyborg.app.command_table import COMMANDS
from cyborg.app.errors import CommandError
from cyborg.bus.component import LaunchError, NodeSpec
from cyborg.interfaces.robot import fleet_namespaces
from cyborg.nav.arnl_map import ArnlMap, MapError, read_map
from cyborg.nav.geometry import Pose2D
from cyborg.nav.planner import Planner
from cyborg.sim import component as sim


def add_parser(commands: Any) -> None:
    """Adds ``cyborg sim`` and ``cyborg nav`` to the commands."""
    parser = commands.add_parser("sim", help=COMMANDS["sim"].help,
                                 description="Simulate the Pioneer LX on a map and serve it "
                                             "on the bus with an ARNL-like interface.")
    parser.add_argument("--map", type=Path, required=True, metavar="FILE",
                        help="ARNL .map file")
    parser.add_argument("--speed", type=float, default=sim.SPEED, metavar="X",
                        help=f"simulated seconds per wall-clock second (default {sim.SPEED:g}; "
                             "0: as fast as possible)")
    parser.add_argument("--start", default=None, metavar="NAME",
                        help="home, goal or dock to start at (default: the map's home, else "
                             "its dock, else the free point nearest the map's centre)")
    parser.add_argument("--namespace", default=sim.NAMESPACE,
                        help=f"the robot's namespace (default {sim.NAMESPACE}); with several "
                             "robots, where their namespaces robot1 ... go (/ for /robot1 ...)")
    parser.add_argument("--robots", type=int, default=sim.ROBOTS, metavar="N",
                        help=f"how many robots to simulate on the map (default {sim.ROBOTS})")
    parser.add_argument("--connect", action="append", default=[], metavar="ENDPOINT",
                        help="join the router there instead of being one")
    parser.add_argument("--listen", default=DEFAULT_ROUTER, metavar="ENDPOINT",
                        help=f"be the bus's router there (default {DEFAULT_ROUTER}); if a "
                             "router already runs there, join it")
    parser.add_argument("--duration", type=float, default=None, metavar="SECONDS",
                        help="stop after this much simulated time")
    parser.set_defaults(handler=sim_command)

    nav = commands.add_parser("nav", help=COMMANDS["nav"].help)
    actions = nav.add_subparsers(dest="nav_command", metavar="COMMAND", required=True)
    goals = actions.add_parser("goals", help="list the goals and docks of a map")
    goals.add_argument("map", type=Path)
    goals.set_defaults(handler=goals_command)
    plan = actions.add_parser("plan", help="plan a path and print its length")
    plan.add_argument("map", type=Path)
    plan.add_argument("start", help="a goal name, or x,y[,heading] (metres, degrees)")
    plan.add_argument("goal", help="a goal name, or x,y[,heading] (metres, degrees)")
    plan.add_argument("--waypoints", action="store_true", help="print the path's points too")
    plan.set_defaults(handler=plan_command)


def load(path: Path) -> ArnlMap:
    """The map at ``path``; an error names the file and line."""
    try:
        return read_map(path)
    except MapError as exc:
        raise CommandError(str(exc)) from exc


def pose_argument(arnl_map: ArnlMap, text: str) -> Pose2D:
    """A goal name, or ``x,y[,heading]`` in metres and degrees."""
    parts = text.split(",")
    if len(parts) in (2, 3):
        try:
            numbers = [float(part) for part in parts]
        except ValueError:
            numbers = []
        if numbers:
            return Pose2D(numbers[0], numbers[1], math.radians(numbers[2]) if len(parts) == 3
                          else 0.0)
    try:
        item = arnl_map.goal(text)
    except KeyError as exc:
        raise CommandError(str(exc).strip("\"'")) from exc
    return Pose2D(item.x, item.y, item.theta)


def goals_command(args: argparse.Namespace) -> int:
    """``cyborg nav goals``: the goals and docks of a map, with their poses."""
    arnl_map = load(args.map)
    print(f"{'name':24} {'kind':16} {'x m':>9} {'y m':>9} {'heading':>8}  description")
    for item in arnl_map.goals():
        heading = f"{math.degrees(item.theta):7.1f}°" if item.has_heading else "       -"
        print(f"{item.name:24} {item.kind:16} {item.x:9.3f} {item.y:9.3f} {heading}  "
              f"{item.description}")
    return 0


def plan_command(args: argparse.Namespace) -> int:
    """``cyborg nav plan``: a path's length between two places, or why there is none."""
    arnl_map = load(args.map)
    start, goal = pose_argument(arnl_map, args.start), pose_argument(arnl_map, args.goal)
    result = Planner(arnl_map).plan(start, goal)
    if result.path is None:
        print(f"no path: {result.code}: {result.reason}")
        return 1
    print(f"{result.length:.2f} m ({len(result.path)} waypoints, planned in "
          f"{result.planning_time * 1000:.1f} ms)")
    if args.waypoints:
        for x, y in result.path.points:
            print(f"  {x:9.3f} {y:9.3f}")
    return 0


def sim_command(args: argparse.Namespace) -> int:
    """``cyborg sim``: the simulator on the bus until Ctrl-C or ``--duration``."""
    if args.speed < 0:
        print("cyborg sim: --speed must be positive (or 0 for as fast as possible)",
              file=sys.stderr)
        return 2
    parameters: dict[str, Any] = {"map": str(args.map), "speed": args.speed}
    if args.start:
        parameters["start"] = args.start
    if args.robots != sim.ROBOTS:
        parameters["robots"] = args.robots
    spec = NodeSpec("simulator", sim.NAME, args.namespace, parameters, where="simulator")
    context, where = bus_context(args.connect, args.listen)
    try:
        try:
            running = sim.start(context, spec)
        except LaunchError as exc:
            raise CommandError(str(exc)) from exc
        try:
            loop = running.loop
            pace = "full speed" if args.speed == 0 else f"{args.speed:g}x real time"
            robots = (f"namespace {args.namespace}" if args.robots == 1 else
                      f"{args.robots} robots under "
                      f"{', '.join(fleet_namespaces(args.namespace, args.robots))}")
            print(f"cyborg sim: {loop.simulator.map.source} at {pace}, {robots}, {where}; "
                  "Ctrl-C stops", flush=True)
            while loop.running:
                if args.duration is not None and loop.simulator.time >= args.duration:
                    break
                time.sleep(0.1)
            if loop.error is not None:
                raise CommandError(f"the simulation stopped: {loop.error}")
        finally:
            running.stop()
    finally:
        context.close()
    return 0
