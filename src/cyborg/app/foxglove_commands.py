"""``cyborg foxglove``: serve the bus to the Foxglove app, live, over its WebSocket protocol.

::

    cyborg foxglove                        # ws://127.0.0.1:8765: Foxglove > Open connection
    cyborg foxglove --port 9090
    cyborg foxglove --host 0.0.0.0 --token-file ~/.config/cyborg/token   # for the network
    cyborg foxglove --connect tcp/robot.local:7447                       # from a laptop

Every topic on the bus is offered with its ROS 2 definition and passed through as it travels;
each robot's map comes as an occupancy grid and as scene lines with its goals, its frame
follows its odometry, and each tree's ticks come as JSON (see docs/foxglove.md). It listens
on this machine only unless ``--host`` says otherwise, which needs a token (``--token-file
PATH`` or ``CYBORG_MONITOR_TOKEN``): clients on other machines connect as
``ws://HOST:8765/?token=...``. Topics, robots and trees that start later are found on the bus.
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
from cyborg.foxglove import component as foxglove


def add_parser(commands: Any) -> None:
    """Adds ``cyborg foxglove`` to the commands."""
    parser = commands.add_parser(
        "foxglove", help=COMMANDS["foxglove"].help,
        description="Serve every topic on the bus, the robots' maps and frames and the trees' "
                    "ticks to the Foxglove app over the Foxglove WebSocket protocol.")
    parser.add_argument("--port", type=int, default=foxglove.PORT,
                        help=f"WebSocket port (default {foxglove.PORT}; 0: any free port)")
    parser.add_argument("--host", default=foxglove.HOST,
                        help=f"address to listen on (default {foxglove.HOST}: this machine "
                             "only; 0.0.0.0: every interface, which needs a token)")
    parser.add_argument("--allow-origin", action="append", default=[], metavar="ORIGIN",
                        help="a web page that may connect from this machine without the token, "
                             "beside the Foxglove app (repeatable; *: any)")
    add_access_options(parser)
    add_token_option(parser)
    add_bus_options(parser)
    parser.set_defaults(handler=foxglove_command)


def foxglove_parameters(args: argparse.Namespace, port: int, host: str) -> dict[str, Any]:
    """The server's launch parameters from the access options (shared with ``cyborg up``)."""
    parameters: dict[str, Any] = {"port": port, "host": host, **access_parameters(args)}
    if getattr(args, "allow_origin", None):
        parameters["allow_origins"] = list(args.allow_origin)
    return parameters


def foxglove_description(args: argparse.Namespace) -> LaunchDescription:
    """What ``cyborg foxglove`` starts, as a launch description.

    A ``--token`` is passed on in memory only (never made a bus parameter), with a warning
    that it shows in ``ps``.
    """
    parameters = foxglove_parameters(args, args.port, args.host)
    add_token(args, parameters)
    return LaunchDescription(
        [NodeSpec("foxglove", foxglove.NAME, foxglove.NAMESPACE, parameters,
                  where="cyborg foxglove")],
        list(args.connect), args.listen or DEFAULT_ROUTER)


def foxglove_command(args: argparse.Namespace) -> int:
    """``cyborg foxglove``: serves the bus to Foxglove until Ctrl-C."""
    return run_system(foxglove_description(args), args, title="cyborg foxglove")
