"""``cyborg monitor``: serve the web monitor for the tree runners on the bus.

::

    cyborg monitor                          # http://127.0.0.1:8080/, trees under /cyborg/bt
    cyborg monitor --port 9000 --namespace /robot1/bt --namespace /robot2/bt
    cyborg monitor --host 0.0.0.0 --token-file ~/.config/cyborg/token   # for the network
    cyborg monitor --connect tcp/robot.local:7447                       # from a laptop

The monitor listens on this machine only (127.0.0.1) unless ``--host`` says otherwise; then it
prints where it listens and whether a token is set. Control from the page is accepted from the
monitor's own page on this machine, or with the token (``--token-file PATH``, or
``CYBORG_MONITOR_TOKEN``; ``--token`` works but shows in ``ps``): a page opened as
``http://HOST:PORT/?token=...`` may control too. Everyone else can watch. The page answers only
to this machine's names and addresses and to names given with ``--allow-host`` (a guard against
DNS rebinding). Tree runners that start later are found on the bus. See docs/security.md.
"""

from __future__ import annotations

import argparse
from typing import Any

from cyborg.app.access_options import (
    access_parameters,
    add_access_options,
    add_token,
    add_token_option,
)
from cyborg.app.bus_options import DEFAULT_ROUTER, add_bus_options
from cyborg.app.command_table import COMMANDS
from cyborg.app.launch import LaunchDescription
from cyborg.app.system import run_system
from cyborg.bus.component import NodeSpec
from cyborg.monitor import component as monitor


def add_parser(commands: Any) -> None:
    """Adds ``cyborg monitor`` to the commands."""
    parser = commands.add_parser(
        "monitor", help=COMMANDS["monitor"].help,
        description="Serve a web page that shows the running behaviour trees live and "
                    "controls them (run/pause, disable, force, breakpoints).")
    parser.add_argument("--port", type=int, default=monitor.PORT,
                        help=f"web server port (default {monitor.PORT}; 0: any free port)")
    parser.add_argument("--host", default=monitor.HOST,
                        help=f"address to listen on (default {monitor.HOST}: this machine "
                             "only; 0.0.0.0: every interface, for other machines)")
    parser.add_argument("--namespace", action="append", default=[], metavar="NS",
                        help="tree runner namespace to follow (repeatable; default "
                             f"{', '.join(monitor.TREES)}); others on the bus are offered too")
    add_access_options(parser)
    add_token_option(parser)
    add_bus_options(parser)
    parser.set_defaults(handler=monitor_command)


def monitor_description(args: argparse.Namespace) -> LaunchDescription:
    """What ``cyborg monitor`` starts, as a launch description.

    A ``--token`` is passed on in memory only (the monitor never makes it a bus parameter),
    with a warning that it shows in ``ps``.
    """
    namespaces = ["/" + namespace.strip("/") for namespace in args.namespace] \
        or list(monitor.TREES)
    parameters: dict[str, Any] = {"trees": namespaces, "port": args.port, "host": args.host,
                                  **access_parameters(args)}
    add_token(args, parameters)
    return LaunchDescription(
        [NodeSpec("monitor", monitor.NAME, monitor.NAMESPACE, parameters,
                  where="cyborg monitor")],
        list(args.connect), args.listen or DEFAULT_ROUTER)


def monitor_command(args: argparse.Namespace) -> int:
    """``cyborg monitor``: serves the web monitor until Ctrl-C."""
    return run_system(monitor_description(args), args, title="cyborg monitor")
