"""The gate's copy of a connection, frame by frame, closing the SDK's advertise-subscribe race.

foxglove-sdk (0.30) sends a new channel's ``advertise`` to a client *before* it records the
channel for that client. A client that subscribes at once — as a panel of an open layout may,
when its topic appears again after a restart — can be quicker than that:
the server answers ``status`` ``Unknown channel ID: N`` and drops the subscription, and the
panel stays empty although the channel exists.

:class:`Resubscriber` copies the two directions of one admitted connection as WebSocket frames
(RFC 6455) rather than bytes. It notes the channels the server advertised to the client and the
client's subscriptions to those channels (so what it keeps is bounded by the channels, however
many subscriptions a client sends); when the server refuses a subscription to a channel it has
advertised as unknown, the frame is not passed on and the subscription is sent again
(:data:`RETRIES` times at most, :data:`RETRY_DELAY` apart), as the client's own frame between
two of its frames. Everything else passes unchanged but for the bound below: frames the client
or server sends that are not whole text frames of the protocol (binary data, fragments,
compressed or malformed frames, text that is not JSON) are copied as they came, and a refusal of
a channel never advertised is passed on.

A client slower than the data it subscribed to gets only what it can take: the gate keeps
reading the server, lets at most :data:`BACKLOG` bytes of message data wait for the client, and
drops (counts in :attr:`Resubscriber.dropped`) a whole binary frame that would pass it, as the
protocol's data may be dropped. Text frames (the protocol's control messages) are never
dropped: they may wait up to another :data:`BACKLOG`, and a client that takes nothing for
:data:`STALL` seconds past that is disconnected. Otherwise the server would queue up to 1,024
messages for the client (foxglove-sdk's backlog), camera images included: about 10 MB a second
of a 500 KB topic at 20 Hz, held until the client leaves.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import logging
import os
import re
import struct
from dataclasses import dataclass, field
from typing import Any

log = logging.getLogger("cyborg.foxglove")

RETRIES = 5
"""Times a refused subscription is sent again before the refusal is passed to the client."""
RETRY_DELAY = 0.02
"""Seconds before a refused subscription is sent again."""
TEXT_LIMIT = 16 * 1024 * 1024
"""The largest text frame read whole to be looked at; larger ones are copied as they come."""
COPY_BLOCK = 1 << 20
"""Bytes copied at a time of a frame that is not looked at."""
BACKLOG = 8 * 1024 * 1024
"""Bytes of message data that may wait for a slow client; further messages are dropped."""
STALL = 30.0
"""Seconds a client may take nothing while twice :data:`BACKLOG` waits for it; then it is
disconnected (its control messages cannot wait without bound)."""
TEXT = 0x1
BINARY = 0x2
_UNKNOWN = re.compile(r"Unknown channel ID: (\d+)")


@dataclass
class FrameHead:
    """A frame's header as it came, and what it says."""

    raw: bytes
    fin: bool
    rsv: int
    opcode: int
    mask: bytes | None
    length: int

    @property
    def plain_text(self) -> bool:
        """A whole, uncompressed text frame."""
        return self.fin and self.rsv == 0 and self.opcode == TEXT


async def read_head(reader: asyncio.StreamReader) -> FrameHead:
    """Reads one frame's header; IncompleteReadError at the end of the stream."""
    first = await reader.readexactly(2)
    raw = bytearray(first)
    length = first[1] & 0x7F
    if length == 126:
        extra = await reader.readexactly(2)
        raw += extra
        length = struct.unpack("!H", extra)[0]
    elif length == 127:
        extra = await reader.readexactly(8)
        raw += extra
        length = struct.unpack("!Q", extra)[0]
    mask = None
    if first[1] & 0x80:
        mask = await reader.readexactly(4)
        raw += mask
    return FrameHead(bytes(raw), bool(first[0] & 0x80), (first[0] >> 4) & 0x7, first[0] & 0x0F,
                     mask, length)


def unmask(payload: bytes, mask: bytes | None) -> bytes:
    """A client's payload as sent (RFC 6455 5.3); masking again masks it."""
    if mask is None or not payload:
        return payload
    repeated = (mask * (len(payload) // 4 + 1))[:len(payload)]
    return (int.from_bytes(payload, "big") ^ int.from_bytes(repeated, "big")).to_bytes(
        len(payload), "big")


def client_text_frame(text: str) -> bytes:
    """One whole text frame as a client sends it (masked, with a fresh key)."""
    payload = text.encode()
    mask = os.urandom(4)
    length = len(payload)
    if length < 126:
        head = bytes([0x80 | TEXT, 0x80 | length])
    elif length < 1 << 16:
        head = bytes([0x80 | TEXT, 0x80 | 126]) + struct.pack("!H", length)
    else:
        head = bytes([0x80 | TEXT, 0x80 | 127]) + struct.pack("!Q", length)
    return head + mask + unmask(payload, mask)


def _json(payload: bytes) -> dict[str, Any] | None:
    try:
        message = json.loads(payload)
    except (ValueError, UnicodeDecodeError):
        return None
    return message if isinstance(message, dict) else None


@dataclass
class Resubscriber:
    """Copies one connection frame by frame; see the module."""

    advertised: set[int] = field(default_factory=set)
    """Channel ids the server advertised to the client and has not withdrawn."""
    asked: dict[int, int] = field(default_factory=dict)
    """The subscription id the client asked for each advertised channel, while subscribed."""
    tries: dict[int, int] = field(default_factory=dict)
    """Subscriptions sent again, by advertised channel id."""
    dropped: int = 0
    """Binary frames (message data) dropped for a client slower than its data."""
    stalled: bool = False
    """Whether the client was disconnected for taking nothing for :data:`STALL` seconds."""
    _to_server: asyncio.Lock = field(default_factory=asyncio.Lock)
    _retries: set[asyncio.Future[None]] = field(default_factory=set)

    async def run(self, client: tuple[asyncio.StreamReader, asyncio.StreamWriter],
                  server: tuple[asyncio.StreamReader, asyncio.StreamWriter]) -> None:
        """Copies both ways until either side closes, then closes both."""
        tasks = [asyncio.ensure_future(self._from_client(client[0], server[1])),
                 asyncio.ensure_future(self._from_server(server[0], client[1], server[1]))]
        try:
            await asyncio.wait(tasks, return_when=asyncio.FIRST_COMPLETED)
        finally:
            for task in tasks:
                task.cancel()
            for writer in (client[1], server[1]):
                writer.close()

    def client_said(self, payload: bytes) -> None:
        """Notes a subscribe or unsubscribe the client sent (its text, unmasked)."""
        message = _json(payload)
        if message is None:
            return
        with contextlib.suppress(TypeError, KeyError, AttributeError, ValueError):
            if message.get("op") == "subscribe":
                for item in message["subscriptions"]:
                    channel = int(item["channelId"])
                    if channel in self.advertised:  # only these are sent again
                        self.asked[channel] = int(item["id"])
            elif message.get("op") == "unsubscribe":
                gone = {int(number) for number in message["subscriptionIds"]}
                self.asked = {channel: number for channel, number in self.asked.items()
                              if number not in gone}

    def server_said(self, payload: bytes) -> int | None:
        """Notes what the server sent (a text frame's payload).

        Returns the channel to subscribe to again in place of passing the frame on (a refusal
        of an advertised channel the client asked for), or None to pass the frame on.
        """
        message = _json(payload)
        if message is None:
            return None
        with contextlib.suppress(TypeError, KeyError, AttributeError, ValueError):
            op = message.get("op")
            if op == "advertise":
                self.advertised.update(int(item["id"]) for item in message["channels"])
            elif op == "unadvertise":
                for gone in {int(n) for n in message["channelIds"]}:
                    self.advertised.discard(gone)
                    self.asked.pop(gone, None)
                    self.tries.pop(gone, None)
            elif op == "status":
                match = _UNKNOWN.fullmatch(str(message.get("message", "")))
                if match is None:
                    return None
                channel = int(match[1])
                if (channel in self.advertised and channel in self.asked
                        and self.tries.get(channel, 0) < RETRIES):
                    self.tries[channel] = self.tries.get(channel, 0) + 1
                    return channel
        return None

    async def _from_client(self, reader: asyncio.StreamReader,
                           upstream: asyncio.StreamWriter) -> None:
        with contextlib.suppress(asyncio.IncompleteReadError, ConnectionError, OSError):
            while True:
                head = await read_head(reader)
                async with self._to_server:  # a subscription sent again goes between frames
                    upstream.write(head.raw)
                    if head.plain_text and head.length <= TEXT_LIMIT:
                        payload = await reader.readexactly(head.length)
                        upstream.write(payload)
                        self.client_said(unmask(payload, head.mask))
                    else:
                        await _copy(reader, upstream, head.length)
                    await upstream.drain()

    async def _from_server(self, reader: asyncio.StreamReader, client: asyncio.StreamWriter,
                           upstream: asyncio.StreamWriter) -> None:
        # writing waits only once twice the backlog waits: data alone never makes it wait
        client.transport.set_write_buffer_limits(high=2 * BACKLOG)
        with contextlib.suppress(asyncio.IncompleteReadError, ConnectionError, OSError):
            try:
                await self._serve(reader, client, upstream)
            except TimeoutError:
                self.stalled = True

    async def _serve(self, reader: asyncio.StreamReader, client: asyncio.StreamWriter,
                     upstream: asyncio.StreamWriter) -> None:
        """Copies the server's frames to the client (TimeoutError: the client took nothing)."""
        while True:
            head = await read_head(reader)
            if head.plain_text and head.length <= TEXT_LIMIT:
                payload = await reader.readexactly(head.length)
                channel = self.server_said(payload)
                if channel is not None:
                    retry = asyncio.ensure_future(self._again(channel, upstream))
                    self._retries.add(retry)
                    retry.add_done_callback(self._retries.discard)
                    continue
                client.write(head.raw + payload)
            elif head.fin and head.rsv == 0 and head.opcode == BINARY \
                    and head.length <= BACKLOG:
                await self._data(head, reader, client)
                continue
            else:
                client.write(head.raw)
                await _copy(reader, client, head.length, STALL)
            await asyncio.wait_for(client.drain(), STALL)

    async def _data(self, head: FrameHead, reader: asyncio.StreamReader,
                    client: asyncio.StreamWriter) -> None:
        """Passes one message-data frame on without waiting, or drops it past the backlog."""
        if client.transport.is_closing():
            raise ConnectionResetError("the client has gone")
        if client.transport.get_write_buffer_size() + head.length > BACKLOG:
            self.dropped += 1
            left = head.length
            while left:
                block = await reader.read(min(COPY_BLOCK, left))
                if not block:
                    raise asyncio.IncompleteReadError(b"", left)
                left -= len(block)
            return
        client.write(head.raw + await reader.readexactly(head.length))

    async def _again(self, channel: int, upstream: asyncio.StreamWriter) -> None:
        await asyncio.sleep(RETRY_DELAY)
        subscription = self.asked.get(channel)
        if subscription is None or channel not in self.advertised:
            return
        log.debug("channel %d: subscribed again (the server had not recorded it yet)", channel)
        frame = client_text_frame(json.dumps({"op": "subscribe", "subscriptions": [
            {"id": subscription, "channelId": channel}]}))
        with contextlib.suppress(ConnectionError, OSError):
            async with self._to_server:
                upstream.write(frame)
                await upstream.drain()


async def _copy(reader: asyncio.StreamReader, writer: asyncio.StreamWriter, length: int,
                stall: float | None = None) -> None:
    """Copies ``length`` bytes of a frame's payload as they come.

    TimeoutError when ``writer`` takes nothing for ``stall`` seconds (None: waits as long).
    """
    left = length
    while left:
        block = await reader.read(min(COPY_BLOCK, left))
        if not block:
            raise asyncio.IncompleteReadError(b"", left)
        writer.write(block)
        left -= len(block)
        await asyncio.wait_for(writer.drain(), stall)
