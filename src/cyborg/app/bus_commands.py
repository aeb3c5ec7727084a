"""``cyborg router|node|topic|service``: the bus from the shell, in the ros2 style.

    cyborg router                          run a Zenoh router (the local meeting point)
    cyborg node list                       nodes alive now (ours and ROS 2 peers)
    cyborg topic list -t                   topics with their types
    cyborg topic echo /robot/battery       print messages as YAML (latched ones too)
    cyborg topic pub /chatter std_msgs/msg/String "{data: hi}" --once
    cyborg topic hz /camera/image
    cyborg service call /add example_interfaces/srv/AddTwoInts "{a: 2, b: 40}"

Every command takes ``--connect ENDPOINT`` to reach another machine's router
(:mod:`cyborg.app.bus_options`; ``cyborg param`` is :mod:`cyborg.app.param_commands`). Types and QoS
come from the graph (:mod:`cyborg.app.bus_lookup`): ``echo`` and ``hz`` wait for a publisher of
a topic not seen yet, ``service call`` for a server.
"""

from __future__ import annotations

import argparse
import sys
import threading
import time
from typing import Any

import yaml

from cyborg.app.bus_lookup import echo_qos, service_type, topic_type
from cyborg.app.bus_options import add_join_command, open_context
from cyborg.app.command_table import COMMANDS
from cyborg.app.errors import CommandError
from cyborg.app.rate_window import RateWindow, hz_line
from cyborg.bus import (
    BusConfig,
    Context,
    MessageValueError,
    Node,
    Publisher,
    Qos,
    ServiceError,
    new_message,
    to_plain,
)
from cyborg.bus.config import DEFAULT_ROUTER, BusConfigError
from cyborg.bus.wire import EntityKind

ARRAY_PREVIEW = 16
"""Items of an array ``topic echo`` prints unless ``--full``."""


def add_parser(commands: Any) -> None:
    """Adds ``cyborg router``, ``node``, ``topic`` and ``service`` to the commands."""
    router = commands.add_parser("router", help=COMMANDS["router"].help)
    router.add_argument("--listen", action="append", default=[], metavar="ENDPOINT",
                        help=f"where to listen (default {DEFAULT_ROUTER}; tcp/[::]:7447 for "
                             "other machines)")
    router.add_argument("--connect", action="append", default=[], metavar="ENDPOINT",
                        help="another router to link to (repeatable)")
    router.set_defaults(handler=router_command)

    node = _group(commands, "node")
    add_join_command(node, "list", "list live nodes", node_list)
    add_join_command(node, "info", "a node's publishers, subscriptions and services",
                     node_info).add_argument("name")

    topic = _group(commands, "topic")
    add_join_command(topic, "list", "list topics", topic_list).add_argument(
        "-t", "--show-types", action="store_true")
    echo = add_join_command(topic, "echo", "print messages of a topic as YAML", topic_echo)
    echo.add_argument("topic")
    echo.add_argument("type", nargs="?", help="message type (default: from the graph, waiting "
                                              "for a publisher if need be)")
    echo.add_argument("--once", action="store_true", help="print one message and exit")
    echo.add_argument("--count", type=int, default=0, help="exit after this many messages")
    echo.add_argument("--timeout", type=float, default=0.0, help="give up after S seconds")
    echo.add_argument("--latched", action="store_true",
                      help="ask for latched messages even if no publisher says it keeps them "
                           "(automatic when one does)")
    echo.add_argument("--full", action="store_true", help="print long arrays in full")
    pub = add_join_command(topic, "pub", "publish a message given as YAML", topic_pub)
    pub.add_argument("topic")
    pub.add_argument("type")
    pub.add_argument("values", nargs="?", default="{}", help="fields as YAML, e.g. '{data: hi}'")
    pub.add_argument("-r", "--rate", type=float, default=1.0, help="messages per second")
    pub.add_argument("--once", action="store_true", help="publish once, then exit")
    pub.add_argument("--times", type=int, default=0, help="publish this many times, then exit")
    pub.add_argument("--latched", action="store_true", help="latched (transient local)")
    hz = add_join_command(topic, "hz", "print the rate of a topic", topic_hz)
    hz.add_argument("topic")
    hz.add_argument("type", nargs="?", help="message type (default: from the graph)")
    hz.add_argument("--duration", type=float, default=0.0, help="stop after S seconds")

    service = _group(commands, "service")
    add_join_command(service, "list", "list services", service_list).add_argument(
        "-t", "--show-types", action="store_true")
    call = add_join_command(service, "call", "call a service with a request given as YAML",
                            service_call)
    call.add_argument("name")
    call.add_argument("type", nargs="?", help="service type (default: from the graph)")
    call.add_argument("values", nargs="?", default="{}")
    call.add_argument("--timeout", type=float, default=5.0,
                      help="seconds to wait for a server, then for the reply (default 5)")


def _group(commands: Any, name: str) -> Any:
    parser = commands.add_parser(name, help=COMMANDS[name].help)
    return parser.add_subparsers(dest=f"{name}_command", metavar="SUBCOMMAND", required=True)


def router_command(args: argparse.Namespace) -> int:
    """``cyborg router``: a Zenoh router for the bus, until Ctrl-C."""
    listen = args.listen or [DEFAULT_ROUTER]
    try:
        context = Context(BusConfig.router(listen, args.connect))
    except BusConfigError as exc:
        raise CommandError(str(exc)) from exc
    except Exception as exc:
        raise CommandError(f"cannot start a router on {', '.join(listen)}: {exc}") from exc
    print(f"cyborg router {context.zid} listening on {', '.join(listen)} (Ctrl-C stops)",
          flush=True)
    try:
        threading.Event().wait()
    finally:
        context.close()
    return 0


def node_list(args: argparse.Namespace) -> int:
    """``cyborg node list``: the nodes alive on the bus now."""
    with open_context(args) as context:
        for name in context.graph.nodes():
            print(name)
    return 0


def node_info(args: argparse.Namespace) -> int:
    """``cyborg node info``: a node's publishers, subscriptions and services."""
    with open_context(args) as context:
        if args.name not in context.graph.nodes():
            raise CommandError(f"no node {args.name!r} (see `cyborg node list`)")
        print(args.name)
        titles = {EntityKind.PUBLISHER: "Publishers", EntityKind.SUBSCRIPTION: "Subscribers",
                  EntityKind.SERVICE_SERVER: "Service Servers",
                  EntityKind.SERVICE_CLIENT: "Service Clients"}
        endpoints = context.graph.node_endpoints(args.name)
        for kind, title in titles.items():
            print(f"  {title}:")
            for entity in sorted({(e.topic, e.type_name) for e in endpoints if e.kind is kind}):
                print(f"    {entity[0]}: {entity[1]}")
    return 0


def topic_list(args: argparse.Namespace) -> int:
    """``cyborg topic list``: the topics on the bus, with their types if asked."""
    with open_context(args) as context:
        _print_names(context.graph.topics(), args.show_types)
    return 0


def service_list(args: argparse.Namespace) -> int:
    """``cyborg service list``: the services on the bus, with their types if asked."""
    with open_context(args) as context:
        _print_names(context.graph.services(), args.show_types)
    return 0


def _print_names(found: dict[str, set[str]], show_types: bool) -> None:
    for name, type_names in sorted(found.items()):
        print(f"{name} [{', '.join(sorted(type_names))}]" if show_types else name)


def _parse_values(text: str) -> dict[str, Any]:
    try:
        data = yaml.safe_load(text) if text.strip() else {}
    except yaml.YAMLError as exc:
        raise CommandError(f"values {text!r} are not YAML: {exc}") from exc
    if data is None:
        return {}
    if not isinstance(data, dict):
        raise CommandError(f"values {text!r}: expected a mapping such as '{{data: hi}}'")
    return data


def _message(context: Context, type_name: str, text: str) -> Any:
    if type_name not in context.types:
        raise CommandError(f"unknown type {type_name!r}")
    try:
        return new_message(context.types, type_name, _parse_values(text))
    except MessageValueError as exc:
        raise CommandError(f"{type_name}: {exc}") from exc


def _shorten(data: Any, full: bool) -> Any:
    if isinstance(data, dict):
        return {key: _shorten(value, full) for key, value in data.items()}
    if isinstance(data, list):
        if not full and len(data) > ARRAY_PREVIEW:
            return [*data[:ARRAY_PREVIEW], f"... ({len(data)} items; --full shows all)"]
        return [_shorten(item, full) for item in data]
    return data


def topic_echo(args: argparse.Namespace) -> int:
    """``cyborg topic echo``: a topic's messages as YAML.

    The type and the durability to ask for come from the graph.
    """
    limit = 1 if args.once else args.count
    with open_context(args) as context:
        started = time.monotonic()
        type_name = args.type or topic_type(context.graph, context.types, args.topic,
                                            command="cyborg topic echo",
                                            timeout=args.timeout or None)
        done = threading.Event()
        seen = [0]

        def show(message: Any) -> None:
            if done.is_set():
                return
            sys.stdout.write(yaml.safe_dump(_shorten(to_plain(message), args.full),
                                            sort_keys=False) + "---\n")
            sys.stdout.flush()
            seen[0] += 1
            if limit and seen[0] >= limit:
                done.set()

        node = Node("cyborg_topic_echo", context=context)
        node.create_subscription(args.topic, type_name, show,
                                 echo_qos(context.graph, args.topic, latched=args.latched))
        left = args.timeout - (time.monotonic() - started)
        finished = done.wait(max(left, 0.0) if args.timeout else None)
        if args.timeout and not finished:
            raise CommandError(f"{args.topic}: {seen[0]} message(s) within {args.timeout:g} s")
    return 0


def topic_pub(args: argparse.Namespace) -> int:
    """``cyborg topic pub``: publishes a message given as YAML, once, N times or on."""
    times = 1 if args.once else args.times
    if args.rate <= 0:
        raise CommandError(f"--rate must be positive, not {args.rate}")
    with open_context(args) as context:
        message = _message(context, args.type, args.values)
        node = Node("cyborg_topic_pub", context=context)
        publisher = node.create_publisher(args.topic, args.type,
                                          Qos.latched() if args.latched else Qos(depth=10))
        if not args.latched and not _reaches_subscribers(publisher, SUBSCRIBER_WAIT):
            print(f"cyborg topic pub: no subscriber of {publisher.topic} within "
                  f"{SUBSCRIBER_WAIT:g} s; publishing anyway", file=sys.stderr)
        sent = 0
        while not times or sent < times:
            publisher.publish(message)
            sent += 1
            print(f"publishing #{sent}: {to_plain(message)}", flush=True)
            if not times or sent < times:
                time.sleep(1.0 / args.rate)
        time.sleep(0.2 if not args.latched else 0.5)  # let the last message leave
    return 0


SUBSCRIBER_WAIT = 3.0
"""Seconds ``cyborg topic pub`` waits for a subscriber before its first message."""


def _reaches_subscribers(publisher: Publisher[Any], timeout: float) -> bool:
    """Whether what ``publisher`` sends reaches a subscriber, waiting up to ``timeout`` s.

    A subscriber in the graph, and matched by Zenoh's routing, which may come a moment after
    the graph lists it: a message sent in that moment reaches nobody (a lost ``--once``).
    """
    deadline = time.monotonic() + timeout
    while not (publisher.subscription_count() > 0 and publisher.matched()):
        if time.monotonic() >= deadline:
            return False
        time.sleep(0.01)
    return True


def topic_hz(args: argparse.Namespace) -> int:
    """``cyborg topic hz``: the rate a topic's messages arrive at, every second."""
    with open_context(args) as context:
        started = time.monotonic()
        type_name = args.type or topic_type(context.graph, context.types, args.topic,
                                            command="cyborg topic hz",
                                            timeout=args.duration or None)
        window = RateWindow(time.monotonic)
        node = Node("cyborg_topic_hz", context=context)
        node.create_subscription(args.topic, type_name, lambda _m: window.arrived(),
                                 Qos(depth=1000))
        while not args.duration or time.monotonic() - started < args.duration:
            time.sleep(1.0)
            print(hz_line(window.report()), flush=True)
    return 0


def service_call(args: argparse.Namespace) -> int:
    """``cyborg service call``: calls a service with a request given as YAML."""
    if args.type and args.type.lstrip().startswith("{"):  # NAME VALUES, type from the graph
        args.type, args.values = None, args.type
    with open_context(args) as context:
        if args.type:  # a wrong type or wrong values are reported before any waiting
            _request(context, args.type, args.values)
        type_name = service_type(context.graph, context.types, args.name, args.type,
                                 timeout=args.timeout)
        request = _request(context, type_name, args.values)
        node = Node("cyborg_service_call", context=context)
        client = node.create_client(args.name, type_name)
        print(f"requester: making request: {to_plain(request)}\n")
        try:
            response = client.call(request, timeout=args.timeout)
        except ServiceError as exc:
            raise CommandError(str(exc)) from exc
        print("response:")
        print(yaml.safe_dump(to_plain(response), sort_keys=False), end="")
    return 0


def _request(context: Context, service: str, text: str) -> Any:
    if service not in context.types.services:
        raise CommandError(f"unknown service type {service!r}")
    return _message(context, f"{service}_Request", text)
