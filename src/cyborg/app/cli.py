"""Entry point of the ``cyborg`` command.

    cyborg up                      the simulated robot, navigation, the patrol tree, the monitor
    cyborg launch FILE             start the nodes a TOML/YAML launch file lists
    cyborg monitor                 the web monitor of running trees (http://127.0.0.1:8080/)
    cyborg foxglove                the bus served to the Foxglove app (ws://127.0.0.1:8765)
    cyborg bt validate FILE        report every problem in a behavior3editor export
    cyborg bt run FILE             tick a tree with a live status line
    cyborg bt dot FILE             the tree as a Graphviz DOT graph
    cyborg bt json FILE            the tree's structure as JSON
    cyborg bt nodes                list the node types trees can use
    cyborg bt serve FILE           run a tree on the bus (topics, enable, control services)
    cyborg bt reload|enable|disable   control a running tree runner
    cyborg router                  run a Zenoh router (the bus's meeting point)
    cyborg node list|info          nodes on the bus (ours and ROS 2 peers)
    cyborg topic list|echo|pub|hz  topics on the bus
    cyborg service list|call       services on the bus
    cyborg param list|get|set      parameters of a node
    cyborg sim --map FILE          the simulated robot on an ARNL map, on the bus
    cyborg nav goals|plan FILE     goals of a map; plan a path and print its length
    cyborg record -o FILE          record the bus into an MCAP file (--recover a cut one)
    cyborg play FILE               play a recording (MCAP, ROS 1 or 2 bag) on the bus again
    cyborg report FILE             an HTML report of a recorded run (tree, path, battery, goals)
    cyborg detect SOURCE           objects and their distance in images, videos, bags, topics
    cyborg detect models list|fetch   known detector models

Exit codes: 0 success, 1 the input has errors, 2 wrong usage, 130 interrupted.
"""

from __future__ import annotations

import argparse
import logging
import sys
from collections.abc import Sequence

from cyborg import __version__
from cyborg.app import (
    bt_commands,
    bus_commands,
    detect_commands,
    foxglove_commands,
    monitor_commands,
    param_commands,
    play_commands,
    record_commands,
    report_commands,
    runner_commands,
    sim_commands,
    up,
)
from cyborg.app.errors import CommandError
from cyborg.app.memory import limit_malloc_arenas


def build_parser() -> argparse.ArgumentParser:
    """The ``cyborg`` command's parser, with every subcommand."""
    parser = argparse.ArgumentParser(
        prog="cyborg", description="Control stack for the NTNU Cyborg robot.")
    parser.add_argument("--version", action="version", version=f"cyborg {__version__}")
    parser.add_argument("-v", "--verbose", action="count", default=0,
                        help="more log output (-vv for debug)")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    up.add_parser(commands)
    monitor_commands.add_parser(commands)
    foxglove_commands.add_parser(commands)
    runner_commands.add_parsers(bt_commands.add_parser(commands))
    bus_commands.add_parser(commands)
    record_commands.add_parser(commands)
    play_commands.add_parser(commands)
    report_commands.add_parser(commands)
    param_commands.add_parser(commands)
    sim_commands.add_parser(commands)
    detect_commands.add_parser(commands)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Runs the ``cyborg`` command with ``argv`` and returns its exit code."""
    limit_malloc_arenas()  # before any thread starts: keeps a long run's memory flat
    parser = build_parser()
    args = parser.parse_args(argv)
    level = (logging.WARNING, logging.INFO, logging.DEBUG)[min(args.verbose, 2)]
    logging.basicConfig(level=level, format="%(levelname)s %(name)s: %(message)s")
    try:
        result: int = args.handler(args)
    except CommandError as exc:
        print(f"cyborg: error: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        return 130
    except BrokenPipeError:  # e.g. `cyborg bt dot FILE | head`
        sys.stderr.close()
        return 0
    return result


if __name__ == "__main__":
    raise SystemExit(main())
