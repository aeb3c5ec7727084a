"""Where the bus is, from the command line: the options that say so and the contexts they open.

Commands that start nodes (``cyborg up``, ``launch``, ``monitor``, ``bt serve``) take
:func:`add_bus_options` and are the bus's router unless told to join one (:func:`bus_context`);
commands that only look at the bus or call it (``cyborg topic``, ``service``, ``param``, ...)
are made by :func:`add_join_command` and join a router (:func:`open_context`).
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable
from typing import Any

from cyborg.app.errors import CommandError
from cyborg.bus import BusConfig, BusConfigError, Context, MessageTypes
from cyborg.bus.config import DEFAULT_ROUTER

__all__ = ["DEFAULT_ROUTER", "add_bus_options", "add_join_command", "bus_context",
           "open_context"]


def add_bus_options(parser: argparse.ArgumentParser) -> None:
    """``--connect``, ``--listen`` and ``--duration``, for every command that starts nodes."""
    parser.add_argument("--connect", action="append", default=[], metavar="ENDPOINT",
                        help="join the router there instead of being one")
    parser.add_argument("--listen", default=None, metavar="ENDPOINT",
                        help=f"be the bus's router there (default {DEFAULT_ROUTER})")
    parser.add_argument("--duration", type=float, default=None, metavar="SECONDS",
                        help="stop after this many wall-clock seconds")


def add_join_command(group: Any, name: str, text: str,
                     handler: Callable[[argparse.Namespace], int]) -> argparse.ArgumentParser:
    """A subcommand of ``group`` that joins the bus to look or call.

    ``--connect`` and ``--wait`` come with it (:func:`open_context` reads them).
    """
    parser: argparse.ArgumentParser = group.add_parser(name, help=text)
    parser.set_defaults(handler=handler)
    parser.add_argument("--connect", action="append", default=[], metavar="ENDPOINT",
                        help=f"router to join (default $CYBORG_CONNECT or {DEFAULT_ROUTER})")
    parser.add_argument("--wait", type=float, default=1.0, metavar="S",
                        help="seconds to wait for the graph to fill (default 1)")
    return parser


def bus_context(connect: list[str], listen: str,
                types: MessageTypes | None = None) -> tuple[Context, str]:
    """A context joining the given router, or being the router at ``listen``, and where it is.

    If a router already runs at ``listen``, the context joins it. ``types``: the message types
    the command uses, as for :func:`open_context`.
    """
    try:
        if connect:
            return (Context(BusConfig.from_environment(connect), types=types),
                    f"connected to {connect[0]}")
        try:
            return Context(BusConfig.router([listen]), types=types), f"router at {listen}"
        except BusConfigError:
            raise
        except Exception:  # the address is taken: a router already runs there
            return (Context(BusConfig.from_environment([listen]), types=types),
                    f"connected to {listen}")
    except BusConfigError as exc:
        raise CommandError(str(exc)) from exc


def open_context(args: argparse.Namespace, types: MessageTypes | None = None) -> Context:
    """A context for a command; waits until the router is reached and the graph settles.

    ``types``: the message types it uses, when the command has made some known already (a
    player, from its recording); the bus's own by default.
    """
    try:
        context = Context(BusConfig.from_environment(args.connect), types=types)
    except BusConfigError as exc:
        raise CommandError(str(exc)) from exc
    deadline = time.monotonic() + max(args.wait, 0.1) + 1.0
    while time.monotonic() < deadline:
        info = context.session.info
        if info.routers_zid() or info.peers_zid():
            break
        time.sleep(0.05)
    else:
        endpoints = ", ".join(context.config.connect) or "(none)"
        context.close()
        raise CommandError(f"no router reachable at {endpoints}; start one with "
                           "`cyborg router` (or `cyborg up`), or pass --connect")
    time.sleep(args.wait)
    return context
