"""Tables keyed by what others send stay bounded, and wrong values get answers, not tracebacks.

The same class of defect as a forged sequence number (``test_bus_hostile.py``): state that grows
with, or breaks on, names and ids a remote sender chooses. Loopback only, every wait bounded.
"""

from __future__ import annotations

import threading
import time
import uuid
from collections.abc import Iterator
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import numpy as np
import pytest
import zenoh

from cyborg.bus import BusConfig, Context, Node, ServiceError, new_message, shm
from cyborg.bus.actions import MAX_RESULT_WAITERS
from cyborg.bus.shm import SlotWriter
from cyborg.bus.wire import data_key
from tests.bus.bus_peer import (
    forged,
    linked_contexts,
    raw_put,
    until_served,
    until_subscribed,
    wait_for,
)

STRING = "std_msgs/msg/String"
ACTION = "cyborg_msgs/action/MoveToGoal"


@pytest.fixture
def pair() -> Iterator[tuple[Context, Context]]:
    with linked_contexts() as contexts:
        yield contexts


@pytest.fixture
def bus() -> Iterator[Context]:
    context = Context(BusConfig.isolated())
    yield context
    context.close()


def test_forged_shared_memory_tokens_leave_nothing_behind(pair: tuple[Context, Context]) -> None:
    victim, attacker = pair
    liveliness = attacker.session.liveliness()
    tokens = [liveliness.declare_token(f"@cyborg_shm/{victim.domain}/{victim.host}/forger/{i}/"
                                       f"%junk{i}") for i in range(200)]
    assert wait_for(lambda: victim.shm_reader_count("/junk199") == 1)
    for token in tokens:
        token.undeclare()
    assert wait_for(lambda: not [t for t in victim._shm_readers if t.startswith("/junk")], 5)


def test_a_forged_token_with_a_bad_type_does_not_break_graph_queries(
        pair: tuple[Context, Context]) -> None:
    victim, attacker = pair
    key = (f"@ros2_lv/{victim.domain}/abc/1/2/MP/%/%/forger/%chatter/not-a-dds-type/"
           "RIHS01_00/::,10:,:,:,,")
    token = attacker.session.liveliness().declare_token(key)
    marker = attacker.session.liveliness().declare_token(
        f"@ros2_lv/{victim.domain}/abc/1/1/NN/%/%/forger")
    assert wait_for(lambda: "/forger" in victim.graph.nodes())
    assert "/chatter" not in victim.graph.topics()  # the bad endpoint was left out
    token.undeclare()
    marker.undeclare()


def test_a_flood_while_the_node_is_busy_keeps_its_queue_bounded(
        pair: tuple[Context, Context]) -> None:
    victim, attacker = pair
    gate = threading.Event()
    node = Node("slow", context=victim)
    subscription = node.create_subscription("/chatter", STRING, lambda message: gate.wait(10))
    until_subscribed(attacker, "/chatter")
    payload = bytes(attacker.types.serialize(
        attacker.types.message_class(STRING)(data="x"), STRING))
    try:
        for _ in range(1000):
            raw_put(attacker, "/chatter", STRING, payload, forged(1))
        assert wait_for(lambda: len(subscription._last_sequence) == 1000, 10)
        assert node.callbacks._queue.qsize() <= subscription.qos.depth + 1
    finally:
        gate.set()


def test_an_oversized_message_goes_inline_not_into_a_slot(
        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(shm, "MAX_SLOT_SIZE", 1 << 21)
    writer = SlotWriter()
    try:
        assert writer.write(1 << 20, lambda view: None) is not None
        assert writer.write((1 << 21) - 8, lambda view: None) is None
    finally:
        writer.close()


# ---------------------------------------------------------------------- actions
def goal_request(types: Any, goal_id: bytes) -> Any:
    return new_message(types, f"{ACTION}_SendGoal_Request", {
        "goal_id": {"uuid": np.frombuffer(goal_id, np.uint8)}, "goal": {"goal_name": "x"}})


def finish(bus: Context, release: threading.Event) -> Any:
    """An action's execute: wait to be released, succeed with an empty result."""
    release.wait(10)
    return new_message(bus.types, f"{ACTION}_Result")


def test_an_action_server_refuses_a_goal_id_it_already_has(bus: Context) -> None:
    release = threading.Event()
    node = Node("robot", context=bus)
    node.create_action_server("move", ACTION, lambda goal: finish(bus, release),
                              max_goals=2)
    send = node.create_client("move/_action/send_goal", f"{ACTION}_SendGoal")
    try:
        same = uuid.uuid4().bytes
        assert send.call(goal_request(bus.types, same)).accepted
        assert not send.call(goal_request(bus.types, same)).accepted  # a replay
        assert send.call(goal_request(bus.types, uuid.uuid4().bytes)).accepted
        assert not send.call(goal_request(bus.types, uuid.uuid4().bytes)).accepted  # 3 > 2
    finally:
        release.set()


def test_result_requests_waiting_for_one_goal_are_capped(bus: Context) -> None:
    release = threading.Event()
    node = Node("robot", context=bus)
    node.create_action_server("move", ACTION, lambda goal: finish(bus, release))
    send = node.create_client("move/_action/send_goal", f"{ACTION}_SendGoal")
    get = Node("asker", context=bus).create_client("move/_action/get_result",
                                                    f"{ACTION}_GetResult")
    goal_id = uuid.uuid4().bytes
    assert send.call(goal_request(bus.types, goal_id)).accepted
    request = new_message(bus.types, f"{ACTION}_GetResult_Request",
                          {"goal_id": {"uuid": np.frombuffer(goal_id, np.uint8)}})
    with ThreadPoolExecutor(MAX_RESULT_WAITERS + 3) as pool:  # all asking at once
        calls = [pool.submit(get.call, request, 10) for _ in range(MAX_RESULT_WAITERS + 3)]
        try:
            assert wait_for(lambda: sum(call.done() for call in calls) == 3, 5)
            for call in (c for c in calls if c.done()):
                with pytest.raises(ServiceError, match="waiting for the result"):
                    call.result()
        finally:
            release.set()
        answered = [call.result(10) for call in calls if call.exception(10) is None]
    assert len(answered) == MAX_RESULT_WAITERS and {r.status for r in answered} == {4}


# ---------------------------------------------------------------------- parameters
def test_garbage_parameter_values_are_refused_in_the_result(bus: Context) -> None:
    node = Node("detector", context=bus)
    node.parameters.declare("threshold", 0.5, limits=(0.0, 1.0))
    types = bus.types
    value = new_message(types, "rcl_interfaces/msg/ParameterValue", {"type": 77})
    parameter = new_message(types, "rcl_interfaces/msg/Parameter", {"name": "threshold"})
    parameter.value = value
    for service in ("set_parameters", "set_parameters_atomically"):
        kind = "".join(part.capitalize() for part in service.split("_"))
        client = node.create_client(f"/detector/{service}", f"rcl_interfaces/srv/{kind}")
        request = types.message_class(f"rcl_interfaces/srv/{kind}_Request")(
            parameters=[parameter])
        response = client.call(request)
        results = response.results if service == "set_parameters" else [response.result]
        assert not results[0].successful and "unknown parameter type 77" in results[0].reason
    assert node.parameters["threshold"] == 0.5


def test_a_long_lived_node_forgets_what_it_destroyed(bus: Context) -> None:
    """Subscriptions, clients and timers made and destroyed one by one (a monitor viewer coming
    and going for days) leave nothing in the node or the context."""
    node = Node("long_lived", context=bus)
    publisher = node.create_publisher("kept", STRING)
    for index in range(300):
        subscription = node.create_subscription(f"viewer{index}", STRING, lambda _m: None)
        client = node.create_client(f"service{index}", "std_srvs/srv/Trigger")
        timer = node.create_timer(60.0, lambda: None)
        subscription.destroy()
        client.destroy()
        timer.cancel()
    assert len(node._entities) <= 40
    assert publisher in node._entities
    assert len(node._timers) <= 1
    assert not [topic for topic in bus._local if "viewer" in topic]
    node.destroy()


def test_calls_to_a_busy_service_are_refused_beyond_a_bound(
        pair: tuple[Context, Context]) -> None:
    """300 calls to a server whose handler is stuck used to queue 300 requests on its node;
    now at most ``max_pending`` wait and the rest get "busy" at once, and the server serves
    again once the handler is free."""
    victim, attacker = pair
    gate, started = threading.Event(), threading.Event()
    node = Node("slow_server", context=victim)

    def stuck(request: Any) -> Any:
        started.set()
        gate.wait(20)
        return new_message(victim.types, "std_srvs/srv/Trigger_Response", {"success": True})

    server = node.create_service("slow", "std_srvs/srv/Trigger", stuck)
    server.max_pending = 8
    until_served(attacker, "/slow")
    key = data_key(attacker.domain, "/slow", "std_srvs/srv/Trigger",
                   attacker.types.hash("std_srvs/srv/Trigger"))
    payload = bytes(attacker.types.serialize(new_message(
        attacker.types, "std_srvs/srv/Trigger_Request", {}), "std_srvs/srv/Trigger_Request"))
    try:
        first = attacker.session.get(key, payload=payload, attachment=forged(1), timeout=30)
        assert started.wait(10), "the first call reaches the handler"  # it runs, none waits
        pending = [first] + [attacker.session.get(key, payload=payload,
                                                  attachment=forged(index + 1), timeout=30)
                             for index in range(1, 40)]
        busy: list[str] = []
        deadline = time.monotonic() + 5
        while len(busy) < 31 and time.monotonic() < deadline:
            for receiver in list(pending):
                try:
                    reply = receiver.try_recv()
                except zenoh.ZError:  # answered and closed
                    pending.remove(receiver)
                    continue
                if reply is not None:
                    pending.remove(receiver)
                    if reply.err is not None:
                        busy.append(reply.err.payload.to_string())
            time.sleep(0.05)
        assert len(busy) == 31, busy  # one handler running, 8 waiting, the rest refused
        assert all("service /slow is busy: 8 requests are waiting" in text for text in busy)
        assert node.callbacks._queue.qsize() <= 8
    finally:
        gate.set()
    client = Node("caller", context=attacker).create_client("/slow", "std_srvs/srv/Trigger")
    assert client.call(new_message(attacker.types, "std_srvs/srv/Trigger_Request", {}),
                       timeout=10).success
    node.destroy()
