"""``cyborg bt serve|reload|enable|disable|stop|mode``: a tree runner on the bus, and its controls.

::

    cyborg bt serve patrol.b3.json --use-sim-time      # tick it; topics under /cyborg/bt
    cyborg bt serve mission.modes.toml                 # or a mode machine (docs/modes.md)
    cyborg bt reload                                   # load the same file again
    cyborg bt reload other.b3.json                     # or another one
    cyborg bt disable                                  # halt: the robot stops
    cyborg bt enable                                   # start afresh
    cyborg bt stop                                     # halt, shown as stopped until enabled
    cyborg bt mode demo --reason "visitors"            # request a mode (as the file allows)
    cyborg bt mode critical --force                    # force one, past everything
    cyborg bt mode --hold                              # hold the current mode (--release)

The runner is the tree runner component (:mod:`cyborg.runner.component`), with its defaults.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from cyborg.app.bus_options import DEFAULT_ROUTER, add_bus_options, open_context
from cyborg.app.errors import CommandError
from cyborg.app.launch import LaunchDescription
from cyborg.app.system import run_system
from cyborg.bus import Node, ServiceError, new_message
from cyborg.bus.component import NodeSpec
from cyborg.interfaces import Service, modes, tree_runner
from cyborg.interfaces.modes import ModeAction
from cyborg.runner import component as runner


def add_parsers(sub: Any) -> None:
    """Adds ``serve``, ``reload``, ``enable``, ``disable``, ``stop``, ``mode`` to ``cyborg bt``."""
    serve = sub.add_parser("serve", help="run a tree on the bus, with its topics and services",
                           description="Tick a tree as the robot's tree runner: latched "
                                       "structure, active ids, enabled flag, per-tick status, "
                                       "enable/reload/control services.")
    serve.add_argument("file", type=Path,
                       help="behavior3editor export, or a mode file (*.toml, docs/modes.md)")
    serve.add_argument("--tree", metavar="ID|TITLE", default="",
                       help="the tree to run (default: the file's selectedTree)")
    serve.add_argument("--rate", type=float, default=runner.RATE, metavar="HZ",
                       help=f"ticks per second (default {runner.RATE:g})")
    serve.add_argument("--namespace", default=runner.NAMESPACE,
                       help=f"the runner's namespace (default {runner.NAMESPACE})")
    serve.add_argument("--robot-namespace", default=runner.ROBOT_NAMESPACE,
                       help=f"the robot's namespace (default {runner.ROBOT_NAMESPACE})")
    serve.add_argument("--use-sim-time", action="store_true",
                       help="tick on simulated time from /clock")
    serve.add_argument("--disabled", action="store_true", help="start disabled")
    serve.add_argument("--nodes", action="append", default=[], metavar="MODULE",
                       help="import this module of node classes first (repeatable)")
    add_bus_options(serve)
    serve.set_defaults(handler=serve_command)

    for name, text in (("reload", "load the running tree's file again (or another file)"),
                       ("enable", "run the tree (from its root)"),
                       ("disable", "halt the tree: running actions stop"),
                       ("stop", "halt the tree and keep it stopped (as the monitor's STOP) "
                                "until `cyborg bt enable`")):
        parser = sub.add_parser(name, help=text)
        if name == "reload":
            parser.add_argument("file", nargs="?", type=Path, default=None,
                                help="another file to run (default: the same file)")
        parser.add_argument("--namespace", default=runner.NAMESPACE,
                            help=f"the runner's namespace (default {runner.NAMESPACE})")
        parser.add_argument("--connect", action="append", default=[], metavar="ENDPOINT",
                            help="router to join (default $CYBORG_CONNECT or "
                                 f"{DEFAULT_ROUTER})")
        parser.add_argument("--wait", type=float, default=0.5, help=argparse.SUPPRESS)
        parser.set_defaults(handler=control_command, action=name)

    mode = sub.add_parser("mode", help="request, force or hold a mode of the runner's machine",
                          description="Ask a tree runner that runs a mode file for a mode: a "
                                      "request is taken where an on_request transition allows "
                                      "it (guards and dwell honoured); --force enters any mode; "
                                      "--hold keeps the current mode until --release.")
    mode.add_argument("mode", nargs="?", default="", help="the mode to enter")
    how = mode.add_mutually_exclusive_group()
    how.add_argument("--force", action="store_true", help="enter the mode past everything")
    how.add_argument("--hold", action="store_true", help="hold the current mode")
    how.add_argument("--release", action="store_true", help="release the hold")
    mode.add_argument("--reason", default="", help="what the transition log says")
    mode.add_argument("--namespace", default=runner.NAMESPACE,
                      help=f"the runner's namespace (default {runner.NAMESPACE})")
    mode.add_argument("--connect", action="append", default=[], metavar="ENDPOINT",
                      help=f"router to join (default $CYBORG_CONNECT or {DEFAULT_ROUTER})")
    mode.add_argument("--wait", type=float, default=0.5, help=argparse.SUPPRESS)
    mode.set_defaults(handler=mode_command)


def serve_command(args: argparse.Namespace) -> int:
    """``cyborg bt serve``: a tree runner on the bus until Ctrl-C."""
    parameters: dict[str, Any] = {
        "tree_file": str(args.file.resolve()), "tree": args.tree, "rate": args.rate,
        "use_sim_time": args.use_sim_time, "robot_namespace": args.robot_namespace,
        "enabled": not args.disabled}
    if args.nodes:
        parameters["nodes"] = list(args.nodes)
    description = LaunchDescription(
        [NodeSpec("tree_runner", runner.NAME, args.namespace, parameters,
                  where=str(args.file))],
        list(args.connect), args.listen or DEFAULT_ROUTER)
    return run_system(description, args, title="cyborg bt serve")


def control_command(args: argparse.Namespace) -> int:
    """``cyborg bt reload|enable|disable|stop``: calls the running tree runner's service."""
    namespace = "/" + args.namespace.strip("/")
    if args.action == "reload":
        contract: Service[Any, Any] = tree_runner.RELOAD
        fields: dict[str, Any] = {"path": str(args.file.resolve()) if args.file else ""}
    elif args.action == "stop":
        contract, fields = tree_runner.STOP, {}
    else:
        contract = tree_runner.ENABLE
        fields = {"data": args.action == "enable"}
    service, kind = contract.full_name(namespace), contract.type_name
    with open_context(args) as context:
        node = Node("cyborg_bt", context=context)
        client = node.create_client(service, kind)
        try:
            reply = client.call(new_message(context.types, f"{kind}_Request", fields),
                                timeout=10.0)
        except ServiceError as exc:
            raise CommandError(f"{exc} (is a tree runner serving {namespace}?)") from exc
    print(reply.message)
    return 0 if reply.success else 1


def mode_command(args: argparse.Namespace) -> int:
    """``cyborg bt mode``: calls the running mode machine's ``mode/set`` service."""
    action = (ModeAction.HOLD if args.hold else ModeAction.RELEASE if args.release
              else ModeAction.FORCE if args.force else ModeAction.REQUEST)
    if action in (ModeAction.REQUEST, ModeAction.FORCE) and not args.mode:
        raise CommandError("name the mode to enter (or give --hold or --release)")
    if action in (ModeAction.HOLD, ModeAction.RELEASE) and args.mode:
        raise CommandError(f"--{action.label} applies to the current mode; name none")
    namespace = "/" + args.namespace.strip("/")
    with open_context(args) as context:
        client = modes.SET_MODE.client(Node("cyborg_bt", context=context), namespace)
        request = modes.SET_MODE.service_type.Request(action=int(action), mode=args.mode,
                                                      reason=args.reason)
        try:
            reply = client.call(request, timeout=10.0)
        except ServiceError as exc:
            raise CommandError(f"{exc} (is a tree runner of a mode file serving "
                               f"{namespace}?)") from exc
    print(f"{reply.message} (mode now: {reply.mode})")
    return 0 if reply.success else 1
