"""``cyborg up`` and ``cyborg launch``: start the robot's system with one command.

``cyborg up`` with no arguments runs the whole system on built-in defaults, in one process:
the simulated Pioneer LX on the bundled campus map (``data/campus.map``, drawn by the project in
ARNL format) with its navigation services, the tree runner with the bundled mission on modes
(``data/campus.modes.toml``: patrol, go charge, stop and call for help, demo — one tree each in
``data/campus_mission.b3.json``, behavior3editor format; docs/modes.md) on simulated
time, the web monitor (http://127.0.0.1:8080/, ``--monitor-port``; this machine only unless
``--monitor-host 0.0.0.0``, see docs/security.md), with ``--foxglove`` a Foxglove server
(ws://127.0.0.1:8765, :mod:`cyborg.app.foxglove_commands`), :data:`DEFAULT_PEOPLE` people
walking on the map (``--people``) and the simulator's camera detecting them, or with
``--camera real`` a camera playing sample stereo frames into the object detector
(:mod:`cyborg.app.up_vision`). ``--map``, ``--tree``, ``--speed``, ``--camera`` and ``--model``
swap the inputs. ``--robots N`` simulates
N robots on the map (:mod:`cyborg.sim.fleet`), ``/robot1`` … ``/robotN``, each with its own
tree runner (``/robot1/bt`` …) on the same mission; one monitor shows them all, and the camera and
detector serve the first. Each next robot's battery starts :data:`FLEET_BATTERY_STEP` % fuller
(``--battery`` is the first's), so that they take turns at the map's one charger. It prints
what runs and where, then a live line of what the tree does; Ctrl-C stops everything cleanly.

The defaults are chosen to *show* the mission, not to mimic a day of it: the battery drains
about 9 % an hour and charging to 90 % takes two hours, so at real time from a full battery the
first recharge would come after seven hours. ``cyborg up`` therefore simulates at 30x real time
from a 33 % charge, just above the bundled mission's 30 % low-battery threshold: the robot
patrols (mode ``normal``) for about forty seconds, goes to charge (``low_battery``), charges
to 60 % in about a minute and a half and patrols again — the whole cycle within three minutes.
Its first lines say so, how to see the other modes (``cyborg bt mode demo``; ``critical``, which
only a failed charge reaches by itself, by an ``emergency`` event), and how to choose otherwise
(``--speed 1 --battery 100``). ``--tree FILE`` runs a plain tree (or another mode file).

``cyborg launch FILE`` starts what a launch description lists (see :mod:`cyborg.app.launch`).
"""

from __future__ import annotations

import argparse
import os
from importlib.resources import files
from pathlib import Path
from typing import Any

from cyborg.app.access_options import access_parameters, add_access_options
from cyborg.app.bus_options import DEFAULT_ROUTER, add_bus_options
from cyborg.app.command_table import COMMANDS
from cyborg.app.errors import CommandError
from cyborg.app.foxglove_commands import foxglove_parameters
from cyborg.app.launch import LaunchDescription, as_child, read_launch, under_robot
from cyborg.app.memory import keep_large_buffers
from cyborg.app.system import run_system
from cyborg.app.up_record import add_record_options, record_nodes
from cyborg.app.up_vision import SIMULATED, add_vision_options, simulated_camera, vision_nodes
from cyborg.bus.component import LaunchError, NodeSpec
from cyborg.foxglove import component as foxglove
from cyborg.interfaces.robot import fleet_namespaces
from cyborg.monitor import component as monitor
from cyborg.runner import component as runner
from cyborg.sim import component as sim
from cyborg.sim.fleet import MAX_ROBOTS

DATA = files("cyborg.app").joinpath("data")
"""The bundled data: the campus map, its mission on modes and the plain patrol tree."""
CAMPUS_MAP = "campus.map"
"""The bundled map, in ARNL format, in :data:`DATA`."""
CAMPUS_MODES = "campus.modes.toml"
"""The bundled mission, a mode file (docs/modes.md) over ``campus_mission.b3.json``, in
:data:`DATA`: what ``cyborg up`` runs unless ``--tree`` says otherwise."""
CAMPUS_TREE = "campus_patrol.b3.json"
"""The bundled patrol-and-recharge tree in one tree (CheckBattery), a behavior3editor export,
in :data:`DATA`: the plain-tree example, ``cyborg up --tree``."""
CAMPUS_THRESHOLD = 30.0
"""The bundled mission's low-battery threshold, percent: below it the robot goes to charge."""
CAMPUS_CHARGED = 60.0
"""The bundled mission's charged threshold, percent: from it the robot patrols again."""
CAMPUS_DEMO_TIME = 600.0
"""Seconds (tree clock) the bundled mission's demo lasts before it patrols again."""
DEFAULT_SPEED = 30.0
"""Simulated seconds per wall-clock second: a patrol round in ~6 s, a full charge in ~4 min."""
DEFAULT_BATTERY = 33.0
"""Start charge, percent: about 20 simulated minutes of patrol above the threshold."""
DEFAULT_PEOPLE = 3
"""People walking at random among the map's goals: a few, for the camera to see."""
FLEET_BATTERY_STEP = 18.0
"""Percent each next robot of several starts fuller: two hours of patrol (9 % an hour), as long
as a recharge takes, so the robots take turns at the map's charger instead of queueing."""


def add_parser(commands: Any) -> None:
    """Adds ``cyborg up`` and ``cyborg launch`` to the commands."""
    up = commands.add_parser("up", help=COMMANDS["up"].help,
                             description="Start the simulated robot on the bundled campus map, "
                                         "its navigation services and the tree runner with the "
                                         "bundled mission on modes (patrol, go charge, stop "
                                         "and call for help, demo).")
    up.add_argument("--map", type=Path, default=None, metavar="FILE",
                    help="ARNL .map file (default: the bundled campus)")
    up.add_argument("--tree", type=Path, default=None, metavar="FILE",
                    help="behavior3editor export or mode file (*.toml) to run (default: the "
                         "bundled mission on modes)")
    up.add_argument("--speed", type=float, default=DEFAULT_SPEED, metavar="X",
                    help=f"simulated seconds per wall-clock second (default {DEFAULT_SPEED:g}, "
                         f"so a recharge shows within a minute; {sim.SPEED:g}: real time; 0: as "
                         "fast as possible)")
    up.add_argument("--start", default=None, metavar="NAME",
                    help="goal or dock to start at (default: the map's home, else its dock)")
    up.add_argument("--battery", type=float, default=DEFAULT_BATTERY, metavar="PERCENT",
                    help=f"battery charge at the start (default {DEFAULT_BATTERY:g}, just "
                         f"above the bundled mission's {CAMPUS_THRESHOLD:g} %% low-battery "
                         "threshold)")
    up.add_argument("--namespace", default=sim.NAMESPACE,
                    help=f"the robot's namespace (default {sim.NAMESPACE})")
    up.add_argument("--robots", type=int, default=sim.ROBOTS, metavar="N",
                    help=f"how many robots to simulate (default {sim.ROBOTS}; several: "
                         f"/robot1 ... /robotN, each with its own tree runner; at most "
                         f"{MAX_ROBOTS})")
    up.add_argument("--people", type=int, default=DEFAULT_PEOPLE, metavar="N",
                    help=f"people walking at random among the map's goals (default "
                         f"{DEFAULT_PEOPLE}; 0: only the map's own)")
    up.add_argument("--monitor-port", type=int, default=monitor.PORT, metavar="PORT",
                    help=f"port of the web monitor (default {monitor.PORT}; 0: any free port)")
    up.add_argument("--monitor-host", default=monitor.HOST, metavar="ADDRESS",
                    help=f"address the web monitor listens on (default {monitor.HOST}: this "
                         "machine only; 0.0.0.0: every interface)")
    up.add_argument("--no-monitor", action="store_true", help="do not start the web monitor")
    up.add_argument("--foxglove", type=int, nargs="?", const=foxglove.PORT, default=None,
                    metavar="PORT", help="also serve the bus to the Foxglove app on this "
                    f"machine (ws://127.0.0.1:PORT, default {foxglove.PORT}; see `cyborg "
                    "foxglove`)")
    add_access_options(up)
    add_vision_options(up)
    add_record_options(up)
    add_bus_options(up)
    up.set_defaults(handler=up_command)

    launch = commands.add_parser("launch", help=COMMANDS["launch"].help,
                                 description="Start the nodes of a TOML or YAML launch file, "
                                             "in one process or several.")
    launch.add_argument("file", type=Path, help="launch file (.toml, .yaml)")
    launch.add_argument("--process", default="main", help=argparse.SUPPRESS)
    add_bus_options(launch)
    launch.set_defaults(handler=launch_command)


def up_description(args: argparse.Namespace) -> LaunchDescription:
    """The system ``cyborg up`` starts, as a launch description."""
    if args.speed < 0:
        raise CommandError("--speed must be positive, or 0 for as fast as possible")
    if not 1 <= args.robots <= MAX_ROBOTS:
        raise CommandError(f"--robots must be from 1 to {MAX_ROBOTS}, not {args.robots}")
    if args.people < 0:
        raise CommandError(f"--people must be 0 or more, not {args.people}")
    if args.robots > 1 and args.namespace != sim.NAMESPACE:
        raise CommandError(f"--namespace names one robot; with --robots {args.robots} the "
                           f"robots are /robot1 ... /robot{args.robots}")
    map_path = args.map or Path(str(DATA.joinpath(CAMPUS_MAP)))
    tree_path = args.tree or Path(str(DATA.joinpath(CAMPUS_MODES)))
    fleet = "/" if args.robots > 1 else under_robot(args.namespace, sim.NAMESPACE)
    namespaces = fleet_namespaces(fleet, args.robots)
    trees = [under_robot(namespace, runner.NAMESPACE) for namespace in namespaces]
    robot: dict[str, Any] = {"map": str(map_path), "speed": args.speed, "battery": args.battery,
                             "people": args.people, **simulated_camera(args),
                             # with recorded frames the people seen are not in the simulated
                             # world: the robot plans around what it sees only with --camera sim
                             "avoid_objects": args.camera == SIMULATED}
    if args.start:
        robot["start"] = args.start
    if args.robots > 1:
        robot["robots"] = args.robots
        robot["battery_step"] = FLEET_BATTERY_STEP
    nodes = [] if args.no_monitor else [
        # first: a taken port stops the launch before the robot moves
        NodeSpec("monitor", monitor.NAME, fleet,
                 {"trees": trees, "port": args.monitor_port,
                  "host": args.monitor_host, **access_parameters(args)},
                 where="monitor (--monitor-port)")]
    if args.foxglove is not None:  # early too: a taken port stops the launch
        nodes.append(NodeSpec("foxglove", foxglove.NAME, fleet,
                              foxglove_parameters(args, args.foxglove, foxglove.HOST),
                              where="foxglove (--foxglove)"))
    nodes.append(NodeSpec("simulator", sim.NAME, fleet, robot,
                          where="simulator (--robots)" if args.robots > 1 else "simulator"))
    nodes += [NodeSpec("tree_runner", runner.NAME, tree_namespace,
                       {"tree_file": str(tree_path), "use_sim_time": True,
                        "robot_namespace": namespace},
                       where="tree runner" + (f" of {namespace}" if args.robots > 1 else ""))
              for namespace, tree_namespace in zip(namespaces, trees, strict=True)]
    nodes += vision_nodes(args, namespaces[0])
    nodes += record_nodes(args, fleet, map_path, tree_path)  # one recorder: all topics
    return LaunchDescription(nodes, list(args.connect), args.listen or DEFAULT_ROUTER)


def up_notes(args: argparse.Namespace) -> list[str]:
    """The lines ``cyborg up`` prints first, under the bus: the pace and the charge it runs at.

    On the bundled mission at the defaults they say too when its modes change, how to see
    the demo and critical modes, and how to choose otherwise (a recharge is seven hours away
    at real time on a full battery); with people and the simulated camera, where to hear the
    patrol greet them.
    """
    pace = "as fast as possible" if args.speed == 0 else f"{args.speed:g}x real time"
    lines = [f"pace         {pace} (--speed), battery at {args.battery:g} % (--battery)"]
    if args.robots > 1:
        charges = ", ".join(f"{min(args.battery + k * FLEET_BATTERY_STEP, 100.0):g}"
                            for k in range(args.robots))
        lines.append(f"robots       {args.robots} (--robots), each with its tree; batteries at "
                     f"{charges} %, so they take turns at the charger")
    if (args.map, args.tree, args.speed, args.battery) == (None, None, DEFAULT_SPEED,
                                                           DEFAULT_BATTERY):
        robot = args.namespace if args.robots == 1 else "/robotN"
        lines += [f"modes        normal: patrol; low_battery below {CAMPUS_THRESHOLD:g} % within "
                  "a minute, charging",
                  f"             to {CAMPUS_CHARGED:g} %, then normal again, within 3 minutes; "
                  "`cyborg bt mode",
                  f"             demo`: the demo for {CAMPUS_DEMO_TIME / args.speed:g} s; "
                  "critical (stops, calls for help",
                  f"             on {robot.rstrip('/')}/help): `emergency` on .../bt/mode/events, "
                  "ended by",
                  "             `help_arrived` (docs/modes.md)",
                  f"             --speed {sim.SPEED:g} --battery {sim.BATTERY:g}: real time"]
    if args.tree is None and args.people > 0 and simulated_camera(args)["camera"]:
        speaker = args.namespace if args.robots == 1 else "/robotN"
        lines += ["greeting     the patrol turns to people within 2 m and says hello:",
                  f"             `cyborg topic echo {speaker.rstrip('/')}/say`"]
    return lines


def up_command(args: argparse.Namespace) -> int:
    """``cyborg up``: the robot's system on built-in defaults, until Ctrl-C."""
    if args.record is not None and args.record_images:
        keep_large_buffers()  # camera frames without a page fault per 4 KiB (app.memory)
    return run_system(up_description(args), args, title="cyborg up", notes=up_notes(args))


def launch_command(args: argparse.Namespace) -> int:
    """``cyborg launch``: what a launch file lists, or, in a child, one process of it."""
    try:
        description = read_launch(args.file)
    except LaunchError as exc:
        raise CommandError(str(exc)) from exc
    if args.process not in description.processes():
        raise CommandError(f"{args.file}: no node runs in process {args.process!r}")
    if args.listen:
        description.listen = args.listen
    if args.connect:
        description.connect = list(args.connect)
    if args.process == "main":
        return run_system(description, args, title=f"cyborg launch {args.file}")
    parent = os.getppid()
    as_child()  # stopped by its parent's SIGTERM, after the parent's tree runners halted
    return run_system(description, args,
                      title=f"cyborg launch {args.file} --process {args.process}",
                      process=args.process, parent=parent)
