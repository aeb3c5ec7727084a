"""``cyborg monitor``: serve the web monitor for the tree runners on the bus.

::

    cyborg monitor                          # http://127.0.0.1:8080/, trees under /cyborg/bt
    cyborg monitor --port 9000 --namespace /robot1/bt --namespace /robot2/bt
    cyborg monitor --connect tcp/robot.local:7447 --token s3cret

Control from the page is accepted from this machine only, unless ``--token`` (or
``CYBORG_MONITOR_TOKEN``) is set: then a page opened as ``http://HOST:PORT/?token=...`` may
control too. Everyone else can watch. Tree runners that start later are found on the bus.
"""

from __future__ import annotations

import argparse
from typing import Any

from cyborg.app.launch import LaunchDescription
from cyborg.app.launchables import NodeSpec
from cyborg.app.sim_commands import DEFAULT_ROUTER
from cyborg.app.up import add_bus_options, run
from cyborg.monitor import DEFAULT_PORT


def add_parser(commands: Any) -> None:
    monitor = commands.add_parser(
        "monitor", help="serve the web monitor for running behaviour trees",
        description="Serve a web page that shows the running behaviour trees live and "
                    "controls them (run/pause, disable, force, breakpoints).")
    monitor.add_argument("--port", type=int, default=DEFAULT_PORT,
                         help=f"web server port (default {DEFAULT_PORT}; 0: any free port)")
    monitor.add_argument("--host", default="0.0.0.0",
                         help="address to listen on (default: every interface; 127.0.0.1 "
                              "keeps the page on this machine)")
    monitor.add_argument("--namespace", action="append", default=[], metavar="NS",
                         help="tree runner namespace to follow (repeatable; default "
                              "/cyborg/bt); others on the bus are offered too")
    monitor.add_argument("--token", default=None,
                         help="let pages on other machines control with ?token=... "
                              "(default: $CYBORG_MONITOR_TOKEN)")
    add_bus_options(monitor)
    monitor.set_defaults(handler=monitor_command)


def monitor_command(args: argparse.Namespace) -> int:
    namespaces = ["/" + namespace.strip("/") for namespace in args.namespace] or ["/cyborg/bt"]
    parameters: dict[str, Any] = {"trees": namespaces, "port": args.port, "host": args.host}
    if args.token:
        parameters["token"] = args.token
    description = LaunchDescription(
        [NodeSpec("monitor", "monitor", "/cyborg", parameters, where="cyborg monitor")],
        list(args.connect), args.listen or DEFAULT_ROUTER)
    return run(description, args, title="cyborg monitor")
