"""A second process for the bus tests: ``python bus_peer.py ROLE ENDPOINT``.

It joins the router at ENDPOINT, sets up what ROLE says, prints ``ready`` and then lives until
its stdin closes (the test ends) or 60 s pass, so a failing test never leaves it behind.

Imported, it also gives the hostile-input tests a second session in the same process
(:func:`linked_contexts`) and the raw tools of an attacker on the network: samples with any
payload and attachment (:func:`raw_put`), service calls with any request (:func:`raw_call`)
and doorbell datagrams (:func:`ring`). Everything stays on loopback.
"""

from __future__ import annotations

import contextlib
import os
import random
import socket
import sys
import threading
import time
from collections.abc import Callable, Iterator
from typing import Any

import numpy as np
import zenoh

from cyborg.bus import BusConfig, Context, Node, Qos, ServerGoal, new_message
from cyborg.bus.doorbell import doorbell_address, encode
from cyborg.bus.wire import Attachment, EntityKind, data_key, fully_qualified


# ---------------------------------------------------------------------- in-process attacker
def wait_for(predicate: Callable[[], object], timeout: float = 5.0) -> bool:
    """Poll ``predicate`` until it is true or ``timeout`` wall seconds pass."""
    deadline = time.monotonic() + timeout
    while not predicate() and time.monotonic() < deadline:
        time.sleep(0.005)
    return bool(predicate())


@contextlib.contextmanager
def linked_contexts() -> Iterator[tuple[Context, Context]]:
    """(victim, attacker): two sessions linked peer to peer over loopback, no router."""
    from tests.ports import local_endpoint  # here: this file also runs as a script
    address = local_endpoint()
    victim = Context(BusConfig(connect=(), listen=(address,)))
    attacker = Context(BusConfig(connect=(address,), listen=()))
    try:
        assert wait_for(lambda: attacker.session.info.peers_zid(), 10), "no loopback link"
        yield victim, attacker
    finally:
        attacker.close()
        victim.close()


def until_subscribed(attacker: Context, topic: str, timeout: float = 5.0) -> None:
    """Wait until the attacker's graph shows a subscription on ``topic``: data then reaches it."""
    assert wait_for(lambda: attacker.graph.count(topic, EntityKind.SUBSCRIPTION) > 0, timeout), \
        f"no subscription on {topic} in the graph"
    time.sleep(0.05)  # the subscriber's declaration travels beside its token


def until_served(attacker: Context, service: str, timeout: float = 5.0) -> None:
    """Wait until the attacker's graph shows a server of ``service``."""
    assert wait_for(lambda: attacker.graph.count(service, EntityKind.SERVICE_SERVER) > 0,
                    timeout), f"no server of {service} in the graph"
    time.sleep(0.05)


def forged(sequence: int, gid: bytes | None = None) -> bytes:
    """An rmw_zenoh attachment with any sequence number and GID (random by default)."""
    return Attachment(sequence, time.time_ns(), gid if gid is not None else os.urandom(16)) \
        .encode()


def raw_put(context: Context, topic: str, type_name: str, payload: bytes,
            attachment: bytes | None) -> None:
    """A sample on ``topic``'s data key, with whatever payload and attachment (blocking when
    the link is congested rather than dropping, so a flood arrives whole)."""
    key = data_key(context.domain, fully_qualified("/", topic), type_name,
                   context.types.hash(type_name))
    context.session.put(key, payload, attachment=attachment,
                        congestion_control=zenoh.CongestionControl.BLOCK)


def raw_call(context: Context, service: str, service_type: str, payload: bytes,
             attachment: bytes | None, timeout: float = 2.0) -> list[Any]:
    """A service request with any bytes; the replies (ok or err), as Zenoh gives them."""
    key = data_key(context.domain, fully_qualified("/", service), service_type,
                   context.types.hash(service_type))
    return list(context.session.get(key, payload=payload, attachment=attachment,
                                    timeout=timeout))


def ring(victim: Context, entity_id: int, attachment: bytes, reference: bytes) -> None:
    """A doorbell datagram to the victim's session, as any local process can send one."""
    with socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM) as sender:
        sender.sendto(encode(entity_id, attachment, reference),
                      doorbell_address(victim.domain, victim.zid))


# ---------------------------------------------------------------------- roles


def talker(node: Node) -> None:
    publisher = node.create_publisher("chatter", "std_msgs/msg/String")
    message = node.types.message_class("std_msgs/msg/String")

    def run() -> None:
        count = 0
        while True:
            count += 1
            publisher.publish(message(data=f"hello {count}"))
            time.sleep(0.02)
    threading.Thread(target=run, daemon=True).start()


def latched(node: Node) -> None:
    publisher = node.create_publisher("status", "std_msgs/msg/String", Qos.latched())
    message = node.types.message_class("std_msgs/msg/String")
    publisher.publish(message(data="first"))
    publisher.publish(message(data="latest"))


def server(node: Node) -> None:
    response = node.types.message_class("example_interfaces/srv/AddTwoInts_Response")
    node.create_service("add", "example_interfaces/srv/AddTwoInts",
                        lambda request: response(sum=request.a + request.b))

    def fail(request: Any) -> Any:
        raise ValueError(f"cannot add {request.a} and {request.b}")
    node.create_service("fail", "example_interfaces/srv/AddTwoInts", fail)


def action(node: Node) -> None:
    result = node.types.message_class("cyborg_msgs/action/MoveToGoal_Result")

    def execute(goal: ServerGoal) -> Any:
        remaining = 5.0
        while remaining > 0:
            if goal.cancel_requested:
                goal.canceled()
                return result(outcome=3, message="canceled")
            goal.publish_feedback(new_message(
                node.types, "cyborg_msgs/action/MoveToGoal_Feedback",
                {"current_pose": {"x": 5.0 - remaining}, "distance_remaining": remaining}))
            remaining -= 0.25
            time.sleep(0.1)
        return result(outcome=1, message=f"reached {goal.request.goal_name}")
    node.create_action_server("move_to_goal", "cyborg_msgs/action/MoveToGoal", execute)


def params(node: Node) -> None:
    node.parameters.declare("confidence_threshold", 0.5, "detections below are dropped",
                            limits=(0.0, 1.0))
    node.parameters.declare("classes", ["person"], "labels to keep")
    string = node.types.message_class("std_msgs/msg/String")
    changes = node.create_publisher("changes", "std_msgs/msg/String", Qos.latched())
    node.parameters.on_change(lambda c: changes.publish(string(data=repr(sorted(c.items())))))


def garbage(node: Node) -> None:
    """Junk on the chatter key, then one good message, repeatedly."""
    context = node.context
    key = f"{context.domain}/chatter/std_msgs::msg::dds_::String_/" + \
        context.types.hash("std_msgs/msg/String")
    good = node.create_publisher("/chatter", "std_msgs/msg/String")
    string = node.types.message_class("std_msgs/msg/String")
    wrong = context.types.serialize(new_message(context.types, "geometry_msgs/msg/Point",
                                                {"x": 1.0}), "geometry_msgs/msg/Point")
    valid = bytes(context.types.serialize(string(data="truncate me please"),
                                          "std_msgs/msg/String"))
    rng = random.Random(7)

    def run() -> None:
        sequence = 1000
        while True:
            sequence += 1
            attachment = Attachment(sequence, time.time_ns(), bytes(16)).encode()
            try:
                for junk in (bytes(rng.randrange(256) for _ in range(40)), valid[:9],
                             bytes(wrong.obj), b""):
                    context.session.put(key, junk, attachment=attachment)
                context.session.put(key, valid, attachment=b"not an attachment")
                good.publish(string(data="good"))
            except (zenoh.ZError, RuntimeError):  # closing down
                return
            time.sleep(0.02)
    threading.Thread(target=run, daemon=True).start()


def image(node: Node) -> None:
    publisher = node.create_publisher("camera/image", "sensor_msgs/msg/Image")
    types = node.types

    def run() -> None:
        frame = 0
        while True:
            frame += 1
            pixels = np.full(1920 * 1080 * 3, frame % 256, dtype=np.uint8)
            message = new_message(types, "sensor_msgs/msg/Image", {
                "header": {"frame_id": str(frame)}, "height": 1080, "width": 1920,
                "encoding": "bgr8", "step": 5760})
            message.data = pixels
            publisher.publish(message)
            time.sleep(0.05)
    threading.Thread(target=run, daemon=True).start()


def idle(node: Node) -> None:
    """Just a node, to be killed."""


ROLES = {"talker": talker, "latched": latched, "server": server, "action": action,
         "params": params, "garbage": garbage, "image": image, "idle": idle}


def main() -> None:
    role, endpoint = sys.argv[1], sys.argv[2]
    context = Context(BusConfig(connect=(endpoint,)))
    node = Node(f"peer_{role}", namespace="/robot", context=context)
    ROLES[role](node)
    while not (context.session.info.routers_zid() or context.session.info.peers_zid()):
        time.sleep(0.02)
    print("ready", flush=True)
    watchdog = threading.Thread(target=sys.stdin.read, daemon=True)
    watchdog.start()
    watchdog.join(60)
    context.close()


if __name__ == "__main__":
    zenoh.init_log_from_env_or("error")
    main()
