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
    cyborg bt reload|enable|disable|stop   control a running tree runner (stop: until enabled)
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
import importlib
import logging
import os
import signal
import sys
import threading
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from types import FrameType
from typing import Any

from cyborg import __version__
from cyborg.app.command_table import COMMANDS, command_in
from cyborg.app.errors import CommandError


def _add_bt(commands: Any) -> None:
    """``cyborg bt``: the files' commands, then the running tree's (serve, reload, ...)."""
    from cyborg.app import bt_commands, runner_commands
    runner_commands.add_parsers(bt_commands.add_parser(commands))


ADDERS: dict[str, Callable[[Any], None]] = {"bt_commands": _add_bt}
"""How a module's commands are added to the parser, where it is not ``module.add_parser``."""


def build_parser(command: str | None = "") -> argparse.ArgumentParser:
    """The ``cyborg`` command's parser.

    Every command is there; ``command`` says which one is built in full, importing its module
    (:mod:`cyborg.app.command_table`): None, none (``cyborg --help`` imports nothing); the
    default ``""``, all of them.
    """
    parser = argparse.ArgumentParser(
        prog="cyborg", description="Control stack for the NTNU Cyborg robot.")
    parser.add_argument("--version", action="version", version=f"cyborg {__version__}")
    parser.add_argument("-v", "--verbose", action="count", default=0,
                        help="more log output (-vv for debug)")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    full = {name for name, entry in COMMANDS.items()
            if command == "" or (command is not None and command in COMMANDS
                                 and entry.module == COMMANDS[command].module)}
    added: set[str] = set()
    for name, entry in COMMANDS.items():
        if name not in full:
            commands.add_parser(name, help=entry.help)  # its options come when it runs
        elif entry.module not in added:
            added.add(entry.module)
            adder = ADDERS.get(entry.module)
            if adder is None:
                adder = importlib.import_module(f"cyborg.app.{entry.module}").add_parser
            adder(commands)
    return parser

def _exit_interrupted(_signum: int, _frame: FrameType | None) -> None:
    os._exit(130)


@contextmanager
def interrupt_ends_at_once() -> Iterator[None]:
    """Within, Ctrl-C (SIGINT) ends the process at once with code 130, saying nothing.

    For the command's start-up, which only imports and parses: nothing is there to stop yet.
    A ``KeyboardInterrupt`` raised inside an import can surface as a traceback of the module
    being imported, or (raised inside code an extension module runs) make the interpreter end
    itself by SIGINT after ``main`` returned 130; exiting from the signal handler avoids both.
    Outside the main thread (where signals cannot be handled) this does nothing.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous: Callable[[int, FrameType | None], object] | int | None = \
        signal.signal(signal.SIGINT, _exit_interrupted)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


def _forget_interrupts_in_strings_run() -> None:
    """Makes the interpreter exit with the code :func:`main` returns after a Ctrl-C.

    CPython marks the interpreter when a ``KeyboardInterrupt`` leaves code run from a string
    (``exec``/``eval`` of text, as ``namedtuple``, ``dataclasses`` and numba's compiler run it),
    even where the exception is caught further up, and then ends the process by SIGINT at exit
    instead of with the code returned. Running any string clears that mark.
    """
    exec("None")


def main(argv: Sequence[str] | None = None) -> int:
    """Runs the ``cyborg`` command with ``argv`` and returns its exit code.

    Ctrl-C ends any command with code 130 and no traceback, during its start-up too (the
    imports of :func:`build_parser` take seconds on a busy machine).
    """
    try:
        with interrupt_ends_at_once():
            from cyborg.app.memory import limit_malloc_arenas
            limit_malloc_arenas()  # before any thread starts: keeps a long run's memory flat
            words = list(sys.argv[1:] if argv is None else argv)
            parser = build_parser(command_in(words))
            args = parser.parse_args(words)
        level = (logging.WARNING, logging.INFO, logging.DEBUG)[min(args.verbose, 2)]
        logging.basicConfig(level=level, format="%(levelname)s %(name)s: %(message)s")
        result: int = args.handler(args)
    except CommandError as exc:
        print(f"cyborg: error: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        result = 130
    except BrokenPipeError:  # e.g. `cyborg bt dot FILE | head`
        sys.stderr.close()
        return 0
    if result == 130:
        _forget_interrupts_in_strings_run()
    return result

if __name__ == "__main__":
    raise SystemExit(main())
