"""What a viewer may cost the monitor (docs/security.md, "Web monitor"): trees followed only
while someone watches and shared between pages, caps per connection and per address, namespace
names checked before they reach the bus, and messages bounded in size, nesting and rate, each
refusal answered as a located ``error``, never a traceback. Ends with a fuzz test (hypothesis)
over WebSocket messages."""

from __future__ import annotations

import json
import logging
import time
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from starlette.websockets import WebSocketDisconnect

from cyborg.bus import BusConfig, Context, Node
from cyborg.bus.component import LaunchError, NodeSpec
from cyborg.bus.wire import EntityKind
from cyborg.monitor.client import QUEUE_BYTES, Client
from cyborg.monitor.component import start as start_monitor
from cyborg.monitor.limits import (
    DEPTH_LIMIT,
    MESSAGE_LIMIT,
    Limits,
    MessageError,
    check_namespace,
    decode,
)
from cyborg.monitor.server import create_app
from cyborg.runner.tree_runner import TreeRunnerNode
from tests.monitor.monitor_protocol import (
    FakeSource,
    bare_hub,
    bus_monitor,
    local_client,
    next_json,
    peer_from_header,
    receive_until,
)
from tests.running_system import wait_until


def _ping(socket: Any, req: int = 999) -> dict[str, Any]:
    """Ping, and return the pong (the connection is alive and in order)."""
    socket.send_json({"t": "ping", "req": req})
    return receive_until(socket, "pong")


# ---------------------------------------------------------------------------------- sources
def test_watching_many_namespaces_leaves_no_subscriptions_behind() -> None:
    """The attack: 300 watches of new namespaces, 132 MiB that stayed. Now a namespace no tree
    runner is in subscribes to nothing."""
    with bus_monitor() as monitor:
        graph = monitor.node.context.graph

        def subscriptions() -> int:
            return sum(1 for entity in graph.entities([EntityKind.SUBSCRIPTION])
                       if entity.topic.endswith("/behavior_tree"))

        wait_until(lambda: subscriptions() == 1, 10, "the configured tree's subscription")
        with local_client(monitor.app) as client:
            for start in range(0, 300, 6):
                with client.websocket_connect("/ws") as socket:
                    for number in range(start, start + 6):
                        socket.send_json({"t": "watch", "ns": f"/attack{number}/bt"})
                        assert receive_until(socket, "runner")["alive"] is False
                    assert sorted(monitor.hub.sources) == ["/cyborg/bt"]
        assert subscriptions() == 1


def test_pages_share_a_tree_which_is_freed_when_its_runner_and_its_pages_are_gone() -> None:
    hub = bare_hub(runners=("/cyborg/bt", "/other/bt"))
    with local_client(create_app(hub)) as client, client.websocket_connect("/ws") as first:
        with client.websocket_connect("/ws") as second:
            for socket in (first, second):
                socket.send_json({"t": "watch", "ns": "/other/bt"})
                receive_until(socket, "snapshot")
            assert FakeSource.created.count("/other/bt") == 1, "one source, two pages"
        wait_until(lambda: len(hub.clients) == 1, 5, "the second page gone")
        FakeSource.running.discard("/other/bt")  # its runner stops
        time.sleep(0.6)
        assert FakeSource.destroyed == [], "the first page still watches"
        first.send_json({"t": "watch", "ns": "/cyborg/bt"})
        receive_until(first, "snapshot")
        assert FakeSource.destroyed == ["/other/bt"], "nobody watches it, no runner is in it"
        assert "/other/bt" not in json.dumps(receive_until(first, "robots"))
        FakeSource.running.discard("/cyborg/bt")
        time.sleep(0.6)
    assert FakeSource.destroyed == ["/other/bt"], "the configured tree is always followed"


def test_a_runner_that_leaves_is_freed_once_nobody_watches_it() -> None:
    hub = bare_hub(runners=("/cyborg/bt", "/gone/bt"))
    with local_client(create_app(hub)) as client, client.websocket_connect("/ws") as page:
        wait_until(lambda: "/gone/bt" in hub.sources, 5, "the runner found on the bus")
        FakeSource.running.discard("/gone/bt")
        wait_until(lambda: "/gone/bt" not in hub.sources, 5, "the departed runner freed")
        assert FakeSource.destroyed == ["/gone/bt"] and _ping(page)["req"] == 999


def test_a_page_waiting_on_a_namespace_gets_the_tree_when_a_runner_starts(
        shared: Path) -> None:
    with bus_monitor() as monitor, local_client(monitor.app) as client, \
            client.websocket_connect("/ws") as socket:
        socket.send_json({"t": "watch", "ns": "/late/bt"})
        assert receive_until(socket, "runner")["alive"] is False
        assert receive_until(socket, "structure")["tree"] is None
        runner = TreeRunnerNode(Node("tree_runner", "/late/bt", context=monitor.node.context),
                                shared / "trees" / "stock_nodes.tree.json")
        runner.start()
        try:
            structure = receive_until(socket, "structure")
            assert structure["ns"] == "/late/bt" and structure["tree"] is not None
            assert receive_until(socket, "tick")["ns"] == "/late/bt"
        finally:
            runner.destroy()


def test_a_page_may_watch_only_so_many_namespaces_no_runner_is_in() -> None:
    hub = bare_hub(limits=Limits(namespaces_per_connection=3))
    with local_client(create_app(hub)) as client, client.websocket_connect("/ws") as socket:
        for number in [0, 1, 2, 1, 0]:
            socket.send_json({"t": "watch", "ns": f"/n{number}/bt", "req": number})
            receive_until(socket, "watching")
        socket.send_json({"t": "watch", "ns": "/cyborg/bt"})
        receive_until(socket, "watching")  # a tree with a runner does not count
        socket.send_json({"t": "watch", "ns": "/n9/bt", "req": 9})
        error = receive_until(socket, "error")
        assert (error["req"], error["command"], error["field"]) == (9, "watch", "ns")
        assert "at most 3 namespaces" in error["message"], error
        assert FakeSource.created == ["/cyborg/bt"], "and none of them cost a source"


def test_connections_per_address_are_capped_with_a_message_to_the_page() -> None:
    hub = bare_hub(limits=Limits(connections_per_address=2))
    app = create_app(hub)
    with local_client(app) as client, client.websocket_connect("/ws") as one, \
            client.websocket_connect("/ws") as two:
        with client.websocket_connect("/ws") as three:
            error = next_json(three)
            assert error["t"] == "error" and "2 connections from 127.0.0.1" in error["message"]
            with pytest.raises(WebSocketDisconnect) as closed:
                next_json(three)
            assert closed.value.code == 1008
        with local_client(app, peer="192.0.2.9") as far, far.websocket_connect("/ws") as s:
            assert _ping(s)["req"] == 999, "another address is counted apart"
        for page in (one, two):
            assert _ping(page)["req"] == 999


@pytest.mark.parametrize("namespace", [
    "/**", "/*/bt", "/a b", "//x", "/x//bt", "x/bt", "/1x", "/x-y", "/x.y", "/ø", "", "/x//", "/",
    "/" + "a" * 300, 5, None, ["/x"], {"ns": "/x"}])
def test_namespace_names_are_checked_before_they_reach_the_bus(namespace: Any) -> None:
    with pytest.raises(ValueError, match="namespace"):
        check_namespace(namespace)


def test_a_wildcard_namespace_is_a_located_error_on_a_real_bus() -> None:
    """``/**`` reached zenoh as a key expression and raised its ZError."""
    assert check_namespace("/robot_1/bt") == "/robot_1/bt"
    assert check_namespace("/robot_1/bt/") == "/robot_1/bt", "one trailing / is dropped"
    with bus_monitor() as monitor, local_client(monitor.app) as client, \
            client.websocket_connect("/ws") as socket:
        for bad in ("/**", "/$*", "/a/**/b"):
            socket.send_json({"t": "watch", "ns": bad, "req": 3})
            error = receive_until(socket, "error")
            assert (error["req"], error["field"]) == (3, "ns")
        assert _ping(socket)["req"] == 999
        assert sorted(monitor.hub.sources) == ["/cyborg/bt"]


def test_a_namespace_to_follow_is_checked_at_start() -> None:
    with Context(BusConfig.isolated()) as context, \
            pytest.raises(LaunchError, match=r"trees: '/\*\*' is not a namespace"):
        start_monitor(context, NodeSpec("monitor", "monitor", "/cyborg",
                                        {"trees": ["/**"], "port": 0}, where="cyborg monitor"))


# ---------------------------------------------------------------------------------- messages
def test_deep_long_binary_and_broken_messages_get_located_errors() -> None:
    with local_client(create_app(bare_hub())) as client, \
            client.websocket_connect("/ws") as socket:
        socket.send_text("[" * 50000)  # raised RecursionError in the ASGI app
        error = receive_until(socket, "error")
        assert error["n"] == 1 and f"deeper than {DEPTH_LIMIT}" in error["message"]
        socket.send_text(json.dumps({"t": "ping", "pad": "x" * MESSAGE_LIMIT}))
        assert "longer than" in receive_until(socket, "error")["message"]
        socket.send_bytes(b"\x00\x01")
        assert "text" in receive_until(socket, "error")["message"]
        socket.send_text('{"t": "watch", "ns": }')
        error = receive_until(socket, "error")
        assert error["n"] == 4 and error["pos"] == 21 and "column 22" in error["message"]
        socket.send_text('{"t": "ping", "req": ' + "9" * 5000 + "}")
        assert receive_until(socket, "error")["n"] == 5
        socket.send_text(json.dumps({"t": "control", "ns": ["/x"], "req": 6}))
        answer = receive_until(socket, "result")
        assert (answer["req"], answer["ok"]) == (6, False)
        socket.send_text(json.dumps({"t": "hello", "seat": "\ud800"}))
        receive_until(socket, "seat")
        assert _ping(socket)["req"] == 999, "and the connection goes on"


def test_decode_bounds_and_locates() -> None:
    assert decode('{"t": "ping", "a": [[["deep enough"]]]}')["t"] == "ping"
    assert decode('{"t": "[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[["}')["t"].startswith("[")
    with pytest.raises(MessageError) as deep:
        decode("[" * (DEPTH_LIMIT + 1) + "]" * (DEPTH_LIMIT + 1))
    assert deep.value.pos == DEPTH_LIMIT
    with pytest.raises(MessageError, match="NaN"):
        decode('{"t": NaN}')


def test_a_flood_of_commands_is_slowed_not_served() -> None:
    hub = bare_hub(limits=Limits(burst=20, rate=5.0))
    with local_client(create_app(hub)) as client, client.websocket_connect("/ws") as socket:
        socket.send_json({"t": "watch", "ns": "/cyborg/bt"})
        receive_until(socket, "snapshot")
        for number in range(60):
            socket.send_json({"t": "refresh", "req": number})
        served = refused = 0
        while served + refused < 60:
            message = next_json(socket)
            served += message["t"] == "snapshot"
            if message["t"] == "error":
                assert "too many messages" in message["message"], message
                refused += 1
        assert served <= 22 and refused >= 38, "refreshes beyond the burst were not served"
        time.sleep(0.5)
        assert _ping(socket)["req"] == 999, "served again once the flood stopped"


def test_pages_that_come_and_go_or_repeat_themselves_cost_other_pages_nothing() -> None:
    """Each connection, release or claim used to be announced to every page, whether or not
    it changed anything: a page reconnecting in a loop flooded the others (and made them
    resync whole trees)."""
    hub = bare_hub()
    with local_client(peer_from_header(create_app(hub))) as client, \
            client.websocket_connect("/ws") as quiet:
        quiet.send_json({"t": "watch", "ns": "/cyborg/bt"})
        receive_until(quiet, "snapshot")
        with client.websocket_connect("/ws", headers={"x-peer": "192.0.2.9"}) as far, \
                client.websocket_connect("/ws") as holder:
            for _ in range(30):
                far.send_json({"t": "release"})  # held by nobody: nothing changes
                holder.send_json({"t": "claim"})  # the first one changes the seat
            _ping(far)
            _ping(holder)
        for _ in range(30):
            with client.websocket_connect("/ws") as passing:
                _ping(passing)
        quiet.send_json({"t": "ping", "req": "end"})
        heard: list[str] = []
        while (message := next_json(quiet))["t"] != "pong":
            heard.append(message["t"])
    assert heard.count("seat") == 2, \
        f"the quiet page heard {heard.count('seat')} seat messages, not 2 (claim, holder left)"


def test_a_client_queue_is_bounded_in_bytes_too() -> None:
    client = Client(1, None, may_control=False)  # type: ignore[arg-type]
    big = "x" * (1 << 20)
    for _ in range(64):
        client.send(big)
    assert client.queued_bytes <= QUEUE_BYTES + len(big), "64 MiB were queued"
    assert client.dropped > 0


def test_exports_are_bounded() -> None:
    with local_client(create_app(bare_hub())) as client:
        huge = client.post("/api/export", content=b"{" + b" " * (2 << 20) + b"}",
                           headers={"content-type": "application/json"})
        assert huge.status_code == 413
        deep = client.post("/api/export", content=b"[" * 50000)
        assert deep.status_code == 400 and "deeper than" in deep.json()["error"]
        bad = client.post("/api/export", json={"ns": "/**", "format": "dot"})
        assert bad.status_code == 400 and "namespace" in bad.json()["error"]


# ---------------------------------------------------------------------------------- fuzz
COMMANDS = ["hello", "watch", "refresh", "history", "claim", "release", "enable", "control",
            "step", "resume", "ping", "nope", ""]
JSON_LEAVES = (st.none() | st.booleans() | st.integers() | st.floats(allow_nan=False)
               | st.text(max_size=40))
JSON_VALUES = st.recursive(JSON_LEAVES, lambda inner: st.lists(inner, max_size=4)
                           | st.dictionaries(st.text(max_size=8), inner, max_size=4),
                           max_leaves=20)
SAMPLES = st.sampled_from(["/cyborg/bt", "/other/bt", "/**", "leaf0", "root", "disable",
                           "force", "breakpoint", "clear", "success", "running", "s3cret"])
FIELD = SAMPLES | JSON_VALUES
COMMAND = st.fixed_dictionaries(
    {"t": st.sampled_from(COMMANDS)},
    optional={name: FIELD for name in ("ns", "id", "action", "status", "on", "once", "keep",
                                       "force", "seat", "req")})
RAW = (st.text(max_size=200) | st.binary(max_size=64)
       | st.integers(1, 3 * DEPTH_LIMIT).map(lambda depth: "[" * depth)
       | st.integers(1, 3 * DEPTH_LIMIT).map(lambda depth: '{"a":' * depth))
MESSAGE = COMMAND.map(json.dumps) | JSON_VALUES.map(json.dumps) | RAW


@settings(max_examples=150, deadline=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large,
                                 HealthCheck.function_scoped_fixture])
@given(messages=st.lists(MESSAGE, min_size=1, max_size=8), holds_seat=st.booleans())
def test_fuzzed_messages_get_answers_never_tracebacks(messages: list[str | bytes],
                                                      holds_seat: bool,
                                                      caplog: pytest.LogCaptureFixture) -> None:
    """Each case is bounded: at most 10 messages and 500 answers, fake trees (no bus)."""
    caplog.clear()
    hub = bare_hub(token="s3cret", limits=Limits(burst=1000))
    first = [json.dumps({"t": "claim"} if holds_seat else {"t": "hello"})]
    with caplog.at_level(logging.DEBUG), local_client(create_app(hub)) as client, \
            client.websocket_connect("/ws") as socket:
        for message in [*first, *messages]:
            if isinstance(message, bytes):
                socket.send_bytes(message)
            else:
                socket.send_text(message)
        socket.send_json({"t": "ping", "req": "end"})
        errors: list[dict[str, Any]] = []
        for _ in range(500):
            answer = next_json(socket)
            if answer["t"] == "pong" and answer["req"] == "end":
                break
            if answer["t"] == "error":
                errors.append(answer)
        else:
            raise AssertionError("no pong: the connection stopped answering")
    for error in errors:
        assert isinstance(error["message"], str) and error["message"]
        assert 2 <= error["n"] <= len(messages) + 1, error
        assert error["message"].startswith(f"message {error['n']}"), error
    tracebacks = [record for record in caplog.records if record.exc_info]
    assert tracebacks == [], tracebacks[0].getMessage() if tracebacks else ""
