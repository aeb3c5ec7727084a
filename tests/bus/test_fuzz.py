"""Fuzzing a live node: garbage on its topics, its shared-memory routes and its services.

A node with subscriptions, services, parameters, an action server and a simulated clock lives
in one session; a second session linked to it on loopback sends what hypothesis makes (at least
100 cases per kind): random bytes and mutated valid CDR, random attachments, slot references
and doorbell datagrams, requests to every service. Afterwards:

* no traceback escaped a callback (Zenoh logs those as ``callback error``) and none was logged
  by the bus (a callback that raised);
* the node still works: a valid message arrives, a valid call is answered.

Every call is bounded by a timeout; everything stays on loopback.
"""

from __future__ import annotations

import logging
import os
import socket
import time
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from rosbags.interfaces import Nodetype

from cyborg.bus import Context, Node, SimClock, doorbell, new_message
from cyborg.bus.clock import CLOCK_TYPE
from cyborg.bus.shm import PREFIX, SHM_DIR, SlotRef
from cyborg.bus.topics import Subscription
from cyborg.bus.wire import Attachment, EntityKind
from tests.bus.bus_peer import linked_contexts, raw_call, raw_put, ring, until_subscribed, wait_for

CASES = settings(max_examples=100, deadline=None, derandomize=True)

TOPICS: dict[str, tuple[str, dict[str, Any]]] = {  # topic -> (type, a valid message)
    "/target/chatter": ("std_msgs/msg/String", {"data": "hello"}),
    "/target/cmd_vel": ("geometry_msgs/msg/Twist", {"linear": {"x": 0.2}}),
    "/target/image": ("sensor_msgs/msg/Image", {"height": 2, "width": 2, "encoding": "mono8",
                                                "step": 2, "data": [1, 2, 3, 4]}),
    "/clock": (CLOCK_TYPE, {"clock": {"sec": 12}}),
}
SERVICES: dict[str, tuple[str, dict[str, Any]]] = {  # service -> (type, a valid request)
    "/add": ("example_interfaces/srv/AddTwoInts", {"a": 1, "b": 2}),
    "/toggle": ("std_srvs/srv/SetBool", {"data": True}),
    "/target/set_parameters": ("rcl_interfaces/srv/SetParameters", {"parameters": [
        {"name": "threshold", "value": {"type": 3, "double_value": 0.7}}]}),
    "/target/get_parameters": ("rcl_interfaces/srv/GetParameters", {"names": ["threshold"]}),
    "/target/describe_parameters": ("rcl_interfaces/srv/DescribeParameters",
                                    {"names": ["threshold", "nope"]}),
    "/target/list_parameters": ("rcl_interfaces/srv/ListParameters", {"prefixes": []}),
    "/move/_action/send_goal": ("cyborg_msgs/action/MoveToGoal_SendGoal",
                                {"goal": {"goal_name": "dock"}}),
    "/move/_action/cancel_goal": ("action_msgs/srv/CancelGoal", {}),
    "/move/_action/get_result": ("cyborg_msgs/action/MoveToGoal_GetResult", {}),
}


class Tracebacks(logging.Handler):
    """Every log record that carries a traceback, or says a Zenoh callback raised."""

    def __init__(self) -> None:
        super().__init__(logging.DEBUG)
        self.records: list[logging.LogRecord] = []

    def emit(self, record: logging.LogRecord) -> None:
        if record.exc_info or "callback error" in record.getMessage():
            self.records.append(record)


@dataclass
class Target:
    victim: Context
    attacker: Context
    node: Node
    clock: SimClock
    tracebacks: Tracebacks
    received: dict[str, list[Any]] = field(default_factory=dict)
    seeds: dict[str, bytes] = field(default_factory=dict)  # topic or service -> valid CDR


def build(victim: Context, attacker: Context, tracebacks: Tracebacks) -> Target:
    node = Node("target", context=victim)
    target = Target(victim, attacker, node, SimClock(node), tracebacks)
    for topic, (type_name, _plain) in TOPICS.items():
        if topic != "/clock":
            seen: list[Any] = []
            target.received[topic] = seen
            node.create_subscription(topic, type_name, seen.append)
    types = victim.types
    add = types.message_class("example_interfaces/srv/AddTwoInts_Response")
    node.create_service("add", "example_interfaces/srv/AddTwoInts",
                        lambda request: add(sum=request.a + request.b))
    toggle = types.message_class("std_srvs/srv/SetBool_Response")
    node.create_service("toggle", "std_srvs/srv/SetBool",
                        lambda request: toggle(success=True, message=str(bool(request.data))))
    node.parameters.declare("threshold", 0.5, limits=(0.0, 1.0))
    result = "cyborg_msgs/action/MoveToGoal_Result"
    node.create_action_server("move", "cyborg_msgs/action/MoveToGoal",
                              lambda goal: new_message(types, result))
    for name, (type_name, plain) in TOPICS.items():
        target.seeds[name] = bytes(types.serialize(new_message(types, type_name, plain),
                                                   type_name))
    for name, (type_name, plain) in SERVICES.items():
        request = new_message(types, f"{type_name}_Request", plain)
        target.seeds[name] = bytes(types.serialize(request, f"{type_name}_Request"))
    for topic in TOPICS:
        until_subscribed(attacker, topic)
    assert wait_for(lambda: all(attacker.graph.count(name, EntityKind.SERVICE_SERVER)
                                for name in SERVICES))
    return target


@pytest.fixture(scope="module")
def target() -> Iterator[Target]:
    catcher = Tracebacks()
    logging.getLogger().addHandler(catcher)
    try:
        with linked_contexts() as (victim, attacker):
            yield build(victim, attacker, catcher)
    finally:
        logging.getLogger().removeHandler(catcher)


@st.composite
def mutated(draw: st.DrawFn, seed: bytes) -> bytes:
    """A valid CDR payload with a few bytes flipped, cut, repeated or inserted; or noise."""
    if draw(st.booleans()):
        return draw(st.binary(max_size=300))
    data = bytearray(seed)
    for _ in range(draw(st.integers(1, 6))):
        where = draw(st.integers(0, len(data)))
        action = draw(st.sampled_from(["flip", "cut", "repeat", "insert", "count"]))
        if action == "flip" and where < len(data):
            data[where] ^= draw(st.integers(1, 255))
        elif action == "cut":
            del data[where:]
        elif action == "repeat":
            data[where:where] = data[where:where + draw(st.integers(1, 16))] * 3
        elif action == "insert":
            data[where:where] = draw(st.binary(min_size=1, max_size=16))
        else:  # a huge element count where one may be
            data[where:where + 4] = draw(st.sampled_from([b"\xff\xff\xff\xff", b"\x00\x00\x00\x80",
                                                          b"\xff\xff\xff\x7f"]))
    return bytes(data)


_INTEGERS = {name: (-(2 ** (bits - 1)), 2 ** (bits - 1) - 1) if name.startswith("int")
             else (0, 2**bits - 1)
             for name, bits in (("int8", 8), ("uint8", 8), ("int16", 16), ("uint16", 16),
                                ("int32", 32), ("uint32", 32), ("int64", 64), ("uint64", 64))}
_INTEGERS["byte"] = _INTEGERS["char"] = (0, 255)
_DTYPES = {"byte": np.uint8, "char": np.uint8, "bool": np.bool_, "float32": np.float32,
           "float64": np.float64, **{name: getattr(np, name) for name in _INTEGERS
                                     if name not in ("byte", "char")}}


def base_values(name: str) -> st.SearchStrategy[Any]:
    """Any value of a ROS base type: NaN and infinities, the extremes, any text."""
    if name in _INTEGERS:
        return st.integers(*_INTEGERS[name])
    if name == "bool":
        return st.booleans()
    if name in ("float32", "float64"):
        return st.floats(width=32 if name == "float32" else 64)
    return st.text(max_size=24)


def field_values(types: Any, kind: Nodetype, detail: Any) -> st.SearchStrategy[Any]:
    if kind == Nodetype.NAME:
        return messages(types, detail)
    if kind == Nodetype.BASE:
        return base_values(detail[0])
    (element_kind, element), bound = detail
    sizes = {"min_size": bound, "max_size": bound} if kind == Nodetype.ARRAY \
        else {"max_size": min(bound, 4) if bound else 4}
    if element_kind == Nodetype.BASE and element[0] in _DTYPES:
        dtype = _DTYPES[element[0]]
        return st.lists(base_values(element[0]), **sizes).map(lambda v: np.array(v, dtype))
    return st.lists(field_values(types, element_kind, element), **sizes)


@st.composite
def messages(draw: st.DrawFn, types: Any, type_name: str) -> Any:
    """A message of ``type_name`` with every field drawn: well-formed CDR, hostile values."""
    fields = {name: draw(field_values(types, kind, detail))
              for name, (kind, detail) in types.store.fielddefs[type_name][1]}
    return types.message_class(type_name)(**fields)


def payloads(types: Any, type_name: str, seed: bytes) -> st.SearchStrategy[bytes]:
    """Broken CDR (:func:`mutated`), or valid CDR of the right type with hostile values."""
    def encode(message: Any) -> bytes:
        try:
            return bytes(types.serialize(message, type_name))
        except Exception:  # e.g. a value out of range for its field: not sendable
            assume(False)
            raise
    return st.one_of(mutated(seed), messages(types, type_name).map(encode))


def attachments() -> st.SearchStrategy[bytes | None]:
    return st.one_of(st.none(), st.binary(max_size=40), st.builds(
        lambda sequence, gid: Attachment(sequence, time.time_ns(), gid).encode(),
        st.integers(-(2**63), 2**63 - 1), st.binary(min_size=16, max_size=16)))


def fresh() -> bytes:
    return Attachment(1, time.time_ns(), os.urandom(16)).encode()


def still_works(target: Target) -> None:
    """A valid message arrives and a valid call is answered, after whatever came before."""
    string = target.attacker.types.message_class("std_msgs/msg/String")
    talker = Node(f"talker{os.urandom(3).hex()}", context=target.attacker)
    publisher = talker.create_publisher("/target/chatter", "std_msgs/msg/String")
    text = f"alive {time.monotonic_ns()}"

    def arrived() -> bool:
        publisher.publish(string(data=text))  # until the new publisher is matched
        return any(m.data == text for m in target.received["/target/chatter"])
    assert wait_for(arrived, 5), "the node stopped receiving"
    client = talker.create_client("/add", "example_interfaces/srv/AddTwoInts")
    request = target.attacker.types.message_class("example_interfaces/srv/AddTwoInts_Request")
    assert client.wait_for_service(5)
    assert client.call(request(a=40, b=2), timeout=5).sum == 42
    assert target.node.callbacks.errors == 0
    talker.destroy()
    assert not target.tracebacks.records, [r.getMessage() for r in target.tracebacks.records]


# ---------------------------------------------------------------------- topics
@CASES
@given(data=st.data())
def test_garbage_payloads_on_every_topic(target: Target, data: st.DataObject) -> None:
    topic = data.draw(st.sampled_from(sorted(TOPICS)))
    type_name = TOPICS[topic][0]
    payload = data.draw(payloads(target.victim.types, type_name, target.seeds[topic]))
    raw_put(target.attacker, topic, type_name, payload, fresh())


@CASES
@given(data=st.data())
def test_garbage_attachments_on_every_topic(target: Target, data: st.DataObject) -> None:
    topic = data.draw(st.sampled_from(sorted(TOPICS)))
    raw_put(target.attacker, topic, TOPICS[topic][0], target.seeds[topic],
            data.draw(attachments()))


def test_the_node_survived_the_topic_fuzz(target: Target) -> None:
    still_works(target)
    assert target.clock.now() < 2**31  # a forged far-future clock never took over


# ---------------------------------------------------------------------- shared memory routes
def references() -> st.SearchStrategy[bytes]:
    paths = st.text(st.characters(codec="utf-8"), max_size=20).map(
        lambda name: f"{SHM_DIR}/{PREFIX}{name}")
    structured = st.builds(lambda path, generation, length: SlotRef(path, generation, length)
                           .encode(), paths, st.integers(0, 2**64 - 1), st.integers(0, 2**64 - 1))
    return st.one_of(st.binary(max_size=120), structured)


@CASES
@given(data=st.data())
def test_garbage_slot_references_through_zenoh(target: Target, data: st.DataObject) -> None:
    topic = data.draw(st.sampled_from(sorted(TOPICS)))
    subscription = next(e for e in target.node._entities
                        if isinstance(e, Subscription) and e.topic == topic)
    target.attacker.session.put(target.victim.shm_key(subscription.key),
                                data.draw(references()), attachment=data.draw(attachments()))


@pytest.mark.skipif(not doorbell.supported(), reason="Linux doorbell only")
@CASES
@given(data=st.data())
def test_garbage_doorbell_datagrams(target: Target, data: st.DataObject) -> None:
    if data.draw(st.booleans()):
        ids = [e.entity_id for e in target.node._entities if hasattr(e, "entity_id")]
        ring(target.victim, data.draw(st.sampled_from(ids)), data.draw(st.binary(max_size=40)),
             data.draw(references()))
    else:
        with socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM) as sender:
            sender.sendto(data.draw(st.binary(max_size=200)),
                          doorbell.doorbell_address(target.victim.domain, target.victim.zid))


def test_the_node_survived_the_shared_memory_fuzz(target: Target) -> None:
    still_works(target)


# ---------------------------------------------------------------------- services
@CASES
@given(data=st.data())
def test_garbage_requests_to_every_service(target: Target, data: st.DataObject) -> None:
    service = data.draw(st.sampled_from(sorted(SERVICES)))
    request_type = f"{SERVICES[service][0]}_Request"
    payload = data.draw(payloads(target.victim.types, request_type, target.seeds[service]))
    replies = raw_call(target.attacker, service, SERVICES[service][0], payload,
                       data.draw(attachments()), timeout=5)
    assert len(replies) == 1, f"{service}: {len(replies)} replies"  # answered, not left hanging
    reply = replies[0]
    if reply.err is not None:
        text = reply.err.payload.to_bytes().decode("utf-8", "replace")
        assert "\n" not in text and "Traceback" not in text, text
        assert text != "Timeout", f"{service}: no answer"


def test_the_node_survived_the_service_fuzz(target: Target) -> None:
    still_works(target)
    values = np.array([target.node.parameters["threshold"]])
    assert np.isfinite(values).all() and 0 <= values[0] <= 1
