"""What the graph tells a bus command before it subscribes or calls: types and durability.

Like ``ros2 topic echo``, ``cyborg topic echo TOPIC`` needs neither the type nor QoS flags:

* the **type** is in every endpoint's liveliness token (``.../<fq_name>/<dds_type>/<hash>/<qos>``,
  see :mod:`cyborg.bus.graph`). If nothing on the topic is alive yet, :func:`topic_type` says on
  stderr that it waits for a publisher, and how to skip that by giving the type; the first
  publisher (or subscription) that appears names it. :func:`service_type` does the same for a
  service's server, as ``ros2 service call`` waits for the service to become available.
* the **durability** is in the token's QoS chunk (``<reliability>:<durability>:...``, ``1`` for
  transient-local). :func:`echo_qos` asks for the latched history when a publisher keeps one.

Messages go to stderr so that stdout stays the command's YAML.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable

from cyborg.app.errors import CommandError
from cyborg.bus import Durability, MessageTypes, Qos
from cyborg.bus.graph import Graph
from cyborg.bus.wire import EntityKind

ECHO_DEPTH = 100
"""Messages an echo may queue, and latched messages it asks each publisher for."""

POLL = 0.5
"""Longest single wait on the graph, so that Ctrl-C is honoured promptly."""


def absolute(name: str) -> str:
    """``chatter`` -> ``/chatter``: names in the graph are fully qualified."""
    return name if name.startswith("/") else "/" + name


def topic_type(graph: Graph, known: MessageTypes, topic: str, *, command: str,
               timeout: float | None) -> str:
    """The type of ``topic``, waiting up to ``timeout`` seconds for an endpoint to appear.

    ``timeout`` None waits for ever; ``command`` (``cyborg topic echo``) is quoted in the hint.
    """
    topic = absolute(topic)
    types = await_types(
        graph, lambda graph: graph.topics().get(topic, set()),
        f"waiting for a publisher of {topic} to learn its type (to skip waiting, give the "
        f"type: {command} {topic} TYPE)", timeout)
    if types is None:
        raise CommandError(f"no publisher of {topic} appeared within {timeout:g} s; is it "
                           "running? (`cyborg topic list`), or give the type to subscribe "
                           "anyway")
    return one_type(known, "topic", topic, types)


def service_type(graph: Graph, known: MessageTypes, service: str, given: str | None, *,
                 timeout: float) -> str:
    """``given``, or the type of ``service`` from its server, once a server is in the graph.

    A call needs a server even when its type is given, so this waits for one either way.
    """
    service = absolute(service)
    types = await_types(graph, lambda graph: graph.services().get(service, set()),
                        f"waiting for service {service} to become available...", timeout)
    if types is None:
        raise CommandError(f"no server of {service} appeared within {timeout:g} s; is it "
                           "running? (`cyborg service list`)")
    return given or one_type(known, "service", service, types)


def await_types(graph: Graph, look: Callable[[Graph], set[str]], waiting: str,
                timeout: float | None) -> set[str] | None:
    """``look(graph)`` once it is not empty; ``None`` if ``timeout`` seconds pass first.

    Says ``waiting`` on stderr if it has to wait at all.
    """
    found = look(graph)
    if found:
        return found
    print(waiting, file=sys.stderr, flush=True)
    deadline = None if timeout is None else time.monotonic() + timeout
    seen: list[set[str]] = []

    def appeared(current: Graph) -> bool:
        seen[:] = [look(current)]
        return bool(seen[0])

    while True:
        remaining = POLL if deadline is None else min(POLL, deadline - time.monotonic())
        if remaining <= 0:
            return None
        if graph.wait_for(appeared, remaining):
            return seen[0]


def one_type(known: MessageTypes, what: str, name: str, types: set[str]) -> str:
    """The single type the graph gives ``name``, if this process knows it."""
    if len(types) != 1:
        raise CommandError(f"{what} {name}: several types ({', '.join(sorted(types))}); "
                           "give one")
    type_name = next(iter(types))
    if type_name not in known:
        raise CommandError(f"{what} {name}: type {type_name} is not registered here")
    return type_name


def echo_qos(graph: Graph, topic: str, *, latched: bool = False) -> Qos:
    """The QoS for watching ``topic``: transient-local when a publisher keeps latched messages.

    ``ros2 topic echo`` asks for transient-local only when *every* publisher offers it, since
    on DDS such a subscription does not match volatile publishers. On Zenoh it does: a
    transient-local subscription is a plain subscriber plus a history query to the latched
    publishers, so it hears everyone. Hence here it is chosen when *any* publisher is latched,
    when ``latched`` forces it (``--latched``), and when no publisher is known yet (one that
    starts later, latched or not, is then heard from its first message on).
    """
    publishers = graph.endpoints(absolute(topic), EntityKind.PUBLISHER)
    if latched or not publishers or any(publisher.latched for publisher in publishers):
        return Qos(durability=Durability.TRANSIENT_LOCAL, depth=ECHO_DEPTH)
    return Qos(depth=ECHO_DEPTH)
