"""``cyborg param list|get|set``: a node's parameters from the shell."""

from __future__ import annotations

import argparse
from collections.abc import Callable
from typing import Any

import yaml

from cyborg.app.bus_options import add_join_command, open_context
from cyborg.app.command_table import COMMANDS
from cyborg.app.errors import CommandError
from cyborg.bus import Node, ServiceError
from cyborg.bus.parameter_client import ParameterClient, ParameterError


def add_parser(commands: Any) -> None:
    """``cyborg param``: its subcommands join the bus (:func:`add_join_command`)."""
    param = commands.add_parser("param", help=COMMANDS["param"].help)
    group = param.add_subparsers(dest="param_command", metavar="SUBCOMMAND", required=True)
    add_join_command(group, "list", "a node's parameters", param_list).add_argument("node")
    get = add_join_command(group, "get", "a parameter's value", param_get)
    get.add_argument("node")
    get.add_argument("name")
    set_ = add_join_command(group, "set", "set a parameter (the value is read as YAML)",
                            param_set)
    set_.add_argument("node")
    set_.add_argument("name")
    set_.add_argument("value")


NODE_WAIT = 5.0
"""Seconds a command waits for a node's parameter services that are not on the bus yet (a node
just started, or a busy machine), as ``ros2 param`` waits for them."""


def _client(args: argparse.Namespace, run: Callable[[ParameterClient], None]) -> int:
    with open_context(args) as context:
        target = args.node if args.node.startswith("/") else "/" + args.node
        client = ParameterClient(Node("cyborg_param", context=context), target)
        if target not in context.graph.nodes() and not client.wait_for_service(NODE_WAIT):
            raise CommandError(f"no node {target!r} (see `cyborg node list`)")
        try:
            run(client)
        except (ParameterError, ServiceError) as exc:
            raise CommandError(str(exc)) from exc
    return 0


def param_list(args: argparse.Namespace) -> int:
    """``cyborg param list``: the names of a node's parameters."""
    return _client(args, lambda client: print(
        "\n".join(f"  {name}" for name in client.names())))


def param_get(args: argparse.Namespace) -> int:
    """``cyborg param get``: a parameter's value, as YAML."""
    def show(client: ParameterClient) -> None:
        value = client.get([args.name])[args.name]
        print(yaml.safe_dump(value, default_flow_style=True).strip().removesuffix("..."
                                                                                   ).strip())
    return _client(args, show)


def param_set(args: argparse.Namespace) -> int:
    """``cyborg param set``: sets a parameter to a value given as YAML."""
    try:
        value = yaml.safe_load(args.value)
    except yaml.YAMLError as exc:
        raise CommandError(f"value {args.value!r} is not YAML: {exc}") from exc

    def apply(client: ParameterClient) -> None:
        client.set({args.name: value})
        print("Set parameter successful")
    return _client(args, apply)
