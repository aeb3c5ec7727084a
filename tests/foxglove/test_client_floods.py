"""A client that floods the server, comes and goes, or does not read: the SDK's lines about it
are limited (one per client and kind, then a count), nothing of a client that left is kept, and
what waits for a slow client is bounded."""

from __future__ import annotations

import asyncio
import gc
import json
import logging
import re
import socket
import struct
from collections.abc import Iterator
from typing import Any

import pytest

from cyborg.bus.msgs.geometry_msgs.msg import Pose2D
from cyborg.bus.topics import Subscription
from cyborg.foxglove import resubscribe
from cyborg.foxglove.resubscribe import BACKLOG, Resubscriber, read_head
from cyborg.foxglove.sdk_log import LIMITER, SDK_CLIENT_LOGGER, TRACKED, RepeatLimiter, classify
from cyborg.interfaces import robot
from cyborg.nav.arnl_map import parse_map
from cyborg.nav.map_message import map_geometry
from tests.foxglove.conftest import Repeating, Served, wait_for
from tests.small_maps import room_map

UNKNOWN = "attempted to subscribe to unknown channel"
SUMMARY = re.compile(r"(\d+) more like this in the last [\d.]+ s \(subscribing to unknown "
                     r"channels\)")


class Clock:
    """A clock the test moves."""

    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


def record(message: str, level: int = logging.ERROR) -> logging.LogRecord:
    return logging.LogRecord(SDK_CLIENT_LOGGER, level, "sdk", 0, message, None, None)


@pytest.fixture
def sdk_lines() -> Iterator[list[logging.LogRecord]]:
    """The records logged on the SDK's client logger (past its filters) while the test runs."""
    said: list[logging.LogRecord] = []

    class Keep(logging.Handler):
        def emit(self, entry: logging.LogRecord) -> None:
            said.append(entry)
    handler = Keep()
    logger = logging.getLogger(SDK_CLIENT_LOGGER)
    logger.addHandler(handler)
    try:
        yield said
    finally:
        logger.removeHandler(handler)


def test_the_sdk_lines_a_client_causes_are_known_and_others_are_not() -> None:
    assert classify(f"Client 127.0.0.1:5 {UNKNOWN}: 7") == ("subscribing to unknown channels",
                                                           "127.0.0.1:5")
    assert classify("Invalid message from [::1]:9: expected value at line 1 column 1") == (
        "invalid messages", "[::1]:9")
    assert classify("Received message for unknown channel: 3") == (
        "messages for unknown channels", "")
    assert classify("Failed to bind socket: address in use") is None
    assert classify("Client 127.0.0.1:5 is not subscribed to channel 3") is None


def test_one_line_per_client_and_kind_passes_in_a_period_then_a_count(
        sdk_lines: list[logging.LogRecord]) -> None:
    clock = Clock()
    limiter = RepeatLimiter(period=10.0, clock=clock)
    lines = [record(f"Client 127.0.0.1:5 {UNKNOWN}: {n}") for n in range(1000)]
    assert [limiter.filter(line) for line in lines[:3]] == [True, False, False]
    assert all(not limiter.filter(line) for line in lines[3:])
    assert limiter.filter(record(f"Client 127.0.0.1:6 {UNKNOWN}: 1"))  # another client
    assert limiter.filter(record("Invalid message from 127.0.0.1:5: x"))  # another kind
    assert limiter.filter(record("Failed to send to 127.0.0.1:5"))  # not a client's doing
    assert limiter.filter(record("Failed to send to 127.0.0.1:5"))
    assert sdk_lines == []
    clock.now += 10.0
    assert limiter.filter(record(f"Client 127.0.0.1:5 {UNKNOWN}: 1000"))  # a new period
    said = [entry.getMessage() for entry in sdk_lines]
    assert said == ["Client 127.0.0.1:5: 999 more like this in the last 10.0 s "
                    "(subscribing to unknown channels)"]
    assert sdk_lines[0].levelno == logging.ERROR
    assert limiter.filter(sdk_lines[0])  # the summary itself passes


def test_a_client_that_leaves_is_summed_up_at_once_and_forgotten(
        sdk_lines: list[logging.LogRecord]) -> None:
    clock = Clock()
    limiter = RepeatLimiter(clock=clock)
    for n in range(5):
        limiter.filter(record(f"Client 127.0.0.1:5 {UNKNOWN}: {n}"))
        limiter.filter(record(f"Client 127.0.0.1:6 {UNKNOWN}: {n}"))
    clock.now += 1.5
    limiter.client_gone("127.0.0.1:5")
    assert [entry.getMessage() for entry in sdk_lines] == [
        "Client 127.0.0.1:5: 4 more like this in the last 1.5 s (subscribing to unknown "
        "channels)"]
    assert limiter.tracked_now() == 1
    limiter.flush()
    assert len(sdk_lines) == 2 and limiter.tracked_now() == 0


def test_a_flood_of_clients_shares_one_count_beyond_the_tracked(
        sdk_lines: list[logging.LogRecord]) -> None:
    limiter = RepeatLimiter(clock=Clock())
    passed = sum(limiter.filter(record(f"Client 10.0.0.1:{port} {UNKNOWN}: 1"))
                 for port in range(10_000))
    assert passed == TRACKED + 1  # the tracked clients, then one for all the others
    assert limiter.tracked_now() == TRACKED + 1
    limiter.flush()
    assert [entry.getMessage() for entry in sdk_lines] == [
        f"Other clients: {10_000 - TRACKED - 1} more like this in the last 0.0 s "
        "(subscribing to unknown channels)"]


def test_a_client_subscribing_to_unknown_channels_gets_one_line_and_a_count(
        served: Served, sdk_lines: list[logging.LogRecord],
        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(LIMITER, "period", 600.0)  # one period for the whole test
    flood = 500
    with served.client() as client:
        for number in range(flood):
            client.connection.send(json.dumps({"op": "subscribe", "subscriptions": [
                {"id": number + 1, "channelId": 100_000 + number}]}))
        client.connection.send("not json")
        assert client.until(lambda: len(client.statuses) == flood + 1)
    assert wait_for(lambda: any(SUMMARY.search(entry.getMessage()) for entry in sdk_lines))
    lines = [entry.getMessage() for entry in sdk_lines]
    passed = [line for line in lines if UNKNOWN in line]
    counted = sum(int(match[1]) for line in lines if (match := SUMMARY.search(line)))
    assert 1 <= len(passed) <= 2  # a line the SDK wrote after the client left starts anew
    assert len(passed) + counted == flood
    assert len(lines) <= 5
    assert any(line.startswith("Invalid message from") for line in lines)  # not hidden


def test_nothing_of_a_client_is_kept_once_it_left(served: Served) -> None:
    node = served.publisher_node
    robot.MAP_GEOMETRY.publisher(node).publish(map_geometry(parse_map(room_map([]), "r.map")))
    robot.ODOM.publisher(node)
    stream = Repeating(robot.POSE.publisher(node), lambda count: Pose2D(x=float(count), y=0.0,
                                                                    theta=0.0))
    topics = ["/cyborg/map", "/cyborg/map_scene", "/cyborg/pose_tf", "/cyborg/pose"]
    try:
        for cycle in range(30):
            with served.client() as client:
                subscriptions = [client.subscribe(topic) for topic in topics]
                client.connection.send(json.dumps({"op": "subscribe", "subscriptions": [
                    {"id": 999, "channelId": 100_000 + cycle}]}))
                client.payloads(subscriptions[0])
                client.payloads(subscriptions[3])
                assert client.until(lambda: bool(client.statuses))
        relays = served.server.relays
        assert wait_for(lambda: relays.subscriptions() == 0)
        assert wait_for(lambda: all(relays.watched(topic) == 0 for topic in topics))

        def alive(kind: type) -> list[Any]:
            gc.collect()
            return [thing for thing in gc.get_objects() if isinstance(thing, kind)]
        assert wait_for(lambda: not alive(Resubscriber))
        # 30 clients opened 150 subscriptions on the bus; the node forgets destroyed ones in
        # batches (Node._keep: once its list doubles past 16), so fewer than 32 may remain
        kept = [thing for thing in alive(Subscription) if thing.node is served.server.node]
        assert len(kept) < 32 and all(thing.closed for thing in kept)
        assert wait_for(lambda: LIMITER.tracked_now() == 0)
    finally:
        stream.stop()


def test_a_client_that_comes_back_finds_the_bus_subscription_still_open(
        served: Served) -> None:
    clock = Clock()
    relays = served.server.relays
    relays.linger, relays.clock = 10.0, clock
    stream = Repeating(served.publisher_node.create_publisher("pose", Pose2D),
                       lambda count: Pose2D(x=float(count), y=0.0, theta=0.0))
    try:
        seen: set[int] = set()
        for _ in range(5):  # a client that reconnects, again and again
            with served.client() as client:
                client.payloads(client.subscribe("/cyborg/pose"))
                seen |= served.subscription_ids("/cyborg/pose")
            assert wait_for(lambda: relays.watched("/cyborg/pose") == 0)
            assert relays.lingering() == 1
        assert len(seen) == 1  # one subscription on the bus for all five
        clock.now += 9.9
        relays.expire()
        assert relays.lingering() == 1
        clock.now += 0.1
        relays.expire()
        assert relays.lingering() == 0
        assert wait_for(lambda: served.subscriptions("/cyborg/pose") == 0)
    finally:
        stream.stop()


def test_a_resubscriber_keeps_only_what_concerns_advertised_channels() -> None:
    watch = Resubscriber()
    watch.server_said(json.dumps({"op": "advertise", "channels": [{"id": 1}, {"id": 2}]})
                      .encode())
    for number in range(10_000):
        watch.client_said(json.dumps({"op": "subscribe", "subscriptions": [
            {"id": number, "channelId": 1000 + number}]}).encode())
    watch.client_said(b'{"op": "subscribe", "subscriptions": [{"id": 7, "channelId": 2}]}')
    assert watch.asked == {2: 7}
    assert watch.server_said(b'{"op": "status", "message": "Unknown channel ID: 2"}') == 2
    watch.server_said(b'{"op": "unadvertise", "channelIds": [2]}')
    assert (watch.asked, watch.tries, watch.advertised) == ({}, {}, {1})


def frame(payload: bytes, opcode: int) -> bytes:
    """A whole frame as a server sends it (unmasked)."""
    return bytes([0x80 | opcode, 127]) + struct.pack("!Q", len(payload)) + payload


async def through_gate(frames: list[bytes],
                       client_reads: bool) -> tuple[Resubscriber, list[bytes]]:
    """``frames`` sent by a server through a Resubscriber to a client that reads them only
    once the server has sent them all (or never); what the client got."""
    client_side, gate_client = socket.socketpair()
    gate_server, server_side = socket.socketpair()
    client = await asyncio.open_connection(sock=client_side)
    server = await asyncio.open_connection(sock=server_side)
    copy = Resubscriber()
    gate = asyncio.ensure_future(copy.run(await asyncio.open_connection(sock=gate_client),
                                          await asyncio.open_connection(sock=gate_server)))

    async def serve() -> None:
        for each in frames:
            server[1].write(each)
            await server[1].drain()
    serving = asyncio.ensure_future(serve())
    got: list[bytes] = []
    if client_reads:
        await asyncio.wait_for(serving, 30)  # the gate read everything, the client nothing
        while not got or got[-1] != b"done":
            head = await read_head(client[0])
            got.append(await client[0].readexactly(head.length))
        client[1].close()
    await asyncio.wait_for(gate, 30)
    serving.cancel()
    client[1].close()
    server[1].close()
    return copy, got


def test_a_slow_client_gets_what_it_can_take_and_the_rest_is_dropped() -> None:
    data = [frame(b"\x01" + bytes(512 * 1024), 0x2) for _ in range(64)]  # 32 MiB of messages
    copy, got = asyncio.run(through_gate([*data, frame(b"done", 0x1)], client_reads=True))
    assert got[-1] == b"done"  # the control message is never dropped
    assert copy.dropped > 0 and len(got) - 1 + copy.dropped == 64
    assert (len(got) - 1) * 512 * 1024 <= BACKLOG + 4 * 1024 * 1024  # and the sockets' own


def test_a_client_that_takes_nothing_is_disconnected(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(resubscribe, "STALL", 0.5)
    text = [frame(b'"' + b"x" * (1024 * 1024) + b'"', 0x1) for _ in range(40)]  # 40 MiB
    copy, _ = asyncio.run(through_gate(text, client_reads=False))
    assert copy.stalled and copy.dropped == 0
