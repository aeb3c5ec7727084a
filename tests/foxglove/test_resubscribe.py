"""The gate's frame-by-frame copy: frames read and written as RFC 6455 lays them out, and a
subscription the server refuses for a channel it has just advertised sent again, unseen by the
client; every other frame passes unchanged."""

from __future__ import annotations

import asyncio
import json
import socket
import struct
from typing import Any

import pytest

from cyborg.bus import Qos
from cyborg.bus.msgs.std_msgs.msg import String
from cyborg.foxglove.resubscribe import (
    RETRIES,
    Resubscriber,
    client_text_frame,
    read_head,
    unmask,
)
from tests.foxglove.conftest import Served


def server_frame(payload: bytes, opcode: int = 0x1, fin: bool = True) -> bytes:
    """A frame as a server sends it (unmasked)."""
    first = (0x80 if fin else 0) | opcode
    if len(payload) < 126:
        return bytes([first, len(payload)]) + payload
    if len(payload) < 1 << 16:
        return bytes([first, 126]) + struct.pack("!H", len(payload)) + payload
    return bytes([first, 127]) + struct.pack("!Q", len(payload)) + payload


def text(message: dict[str, Any]) -> bytes:
    return json.dumps(message).encode()


@pytest.mark.parametrize("length", [0, 1, 125, 126, 65535, 65536, 70001])
def test_a_client_frame_reads_back_as_written(length: int) -> None:
    payload = bytes(range(256)) * (length // 256 + 1)
    payload = payload[:length]
    frame = client_text_frame(payload.decode("latin-1"))

    async def read() -> tuple[Any, bytes]:
        reader = asyncio.StreamReader()
        reader.feed_data(frame)
        reader.feed_eof()
        head = await read_head(reader)
        return head, await reader.readexactly(head.length)
    head, body = asyncio.run(read())
    assert head.plain_text and head.mask is not None
    assert unmask(body, head.mask).decode() == payload.decode("latin-1")
    assert head.raw + body == frame


def test_only_a_refusal_of_an_advertised_channel_the_client_asked_for_is_taken() -> None:
    watch = Resubscriber()
    refusal = text({"op": "status", "level": 2, "message": "Unknown channel ID: 7"})
    assert watch.server_said(refusal) is None  # neither advertised nor asked for
    watch.server_said(text({"op": "advertise", "channels": [{"id": 7, "topic": "/a"}]}))
    assert watch.server_said(refusal) is None  # not asked for: the client's own mistake
    watch.client_said(text({"op": "subscribe", "subscriptions": [{"id": 3, "channelId": 7}]}))
    assert [watch.server_said(refusal) for _ in range(RETRIES + 1)] == [7] * RETRIES + [None]
    watch.client_said(text({"op": "unsubscribe", "subscriptionIds": [3]}))
    assert watch.asked == {}
    watch.server_said(text({"op": "unadvertise", "channelIds": [7]}))
    assert watch.advertised == set()
    for garbage in (b"", b"{", b"[1, 2]", b"\xff\xfe", text({"op": "subscribe"}),
                    text({"op": "subscribe", "subscriptions": [{"id": "x", "channelId": None}]}),
                    text({"op": "advertise", "channels": 5}), text({"op": "status"})):
        watch.client_said(garbage)
        assert watch.server_said(garbage) is None


class FakeServer:
    """The SDK's side of one connection: advertises a channel, refuses the first subscribe."""

    def __init__(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        self.reader, self.writer = reader, writer
        self.subscribes: list[dict[str, Any]] = []

    async def serve(self) -> None:
        self.writer.write(server_frame(text({"op": "advertise", "channels": [{"id": 7}]})))
        self.writer.write(server_frame(b"\x01" + bytes(70000), opcode=0x2))  # binary data
        self.writer.write(server_frame(b"frag", fin=False) + server_frame(b"ment", opcode=0))
        while True:
            head = await read_head(self.reader)
            message = json.loads(unmask(await self.reader.readexactly(head.length), head.mask))
            self.subscribes.append(message)
            if len(self.subscribes) == 1:
                self.writer.write(server_frame(text({"op": "status", "level": 2,
                                                     "message": "Unknown channel ID: 7"})))
            else:
                self.writer.write(server_frame(text({"op": "done"})))
            await self.writer.drain()


def test_a_refused_subscription_is_sent_again_and_the_client_sees_only_the_rest() -> None:
    async def scenario() -> tuple[list[bytes], FakeServer]:
        client_side, gate_client = socket.socketpair()
        gate_server, server_side = socket.socketpair()
        client = await asyncio.open_connection(sock=client_side)
        server = FakeServer(*await asyncio.open_connection(sock=server_side))
        gate = asyncio.ensure_future(Resubscriber().run(
            await asyncio.open_connection(sock=gate_client),
            await asyncio.open_connection(sock=gate_server)))
        serving = asyncio.ensure_future(server.serve())
        seen: list[bytes] = []
        for _ in range(4):  # the advertise, the binary frame, the two fragments
            head = await read_head(client[0])
            seen.append(head.raw + await client[0].readexactly(head.length))
        client[1].write(client_text_frame(json.dumps(
            {"op": "subscribe", "subscriptions": [{"id": 1, "channelId": 7}]})))
        head = await asyncio.wait_for(read_head(client[0]), 30)
        seen.append(await client[0].readexactly(head.length))
        client[1].close()
        await asyncio.wait_for(gate, 30)
        serving.cancel()
        return seen, server
    seen, server = asyncio.run(scenario())
    assert seen[1] == server_frame(b"\x01" + bytes(70000), opcode=0x2)
    assert seen[2] + seen[3] == server_frame(b"frag", fin=False) + server_frame(b"ment", opcode=0)
    assert json.loads(seen[4]) == {"op": "done"}  # never the refusal
    assert server.subscribes == [{"op": "subscribe",
                                  "subscriptions": [{"id": 1, "channelId": 7}]}] * 2


def test_a_client_that_subscribes_the_moment_a_channel_is_advertised_gets_its_messages(
        served: Served) -> None:
    """Topics appear while a client is connected, and it subscribes to each as soon as it
    reads the advertise, as the Foxglove app does: each subscription delivers, and no refusal
    reaches the client (the race itself is rare on a real server; the fake one above makes it
    every time)."""
    latched = Qos.latched()
    with served.client() as client:
        assert client.until(lambda: client.server_info is not None)
        for number in range(12):
            served.publisher_node.create_publisher(f"appears_{number}", String, latched).publish(
                String(data=f"hello {number}"))
            subscription = client.subscribe(f"/cyborg/appears_{number}")
            payload = client.payloads(subscription)[0]
            assert served.context.types.deserialize(payload, "std_msgs/msg/String").data == \
                f"hello {number}"
        assert not [s for s in client.statuses if "Unknown channel" in str(s.get("message"))]
