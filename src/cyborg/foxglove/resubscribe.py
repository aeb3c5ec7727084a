"""The gate's copy of a connection, frame by frame, closing the SDK's advertise-subscribe race.

foxglove-sdk (0.30) sends a new channel's ``advertise`` to a client *before* it records the
channel for that client. A client that subscribes at once — as a panel of an open layout may,
when its topic appears again after a restart — can be quicker than that:
the server answers ``status`` ``Unknown channel ID: N`` and drops the subscription, and the
panel stays empty although the channel exists.

:class:`Resubscriber` copies the two directions of one admitted connection as WebSocket frames
(RFC 6455) rather than bytes. It notes the channels the server advertised to the client and the
subscriptions the client asked for; when the server refuses a subscription to a channel it has
advertised as unknown, the frame is not passed on and the subscription is sent again
(:data:`RETRIES` times at most, :data:`RETRY_DELAY` apart), as the client's own frame between
two of its frames. Everything else passes unchanged: frames the client or server sends that are
not whole text frames of the protocol (binary data, fragments, compressed or malformed frames,
text that is not JSON) are copied as they came, and a refusal of a channel never advertised is
passed on.
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
TEXT = 0x1
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
    """The subscription id the client asked for each channel, while it is subscribed."""
    tries: dict[int, int] = field(default_factory=dict)
    """Subscriptions sent again, by channel id."""
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
                    self.asked[int(item["channelId"])] = int(item["id"])
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
                self.advertised.difference_update(int(n) for n in message["channelIds"])
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
        with contextlib.suppress(asyncio.IncompleteReadError, ConnectionError, OSError):
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
                else:
                    client.write(head.raw)
                    await _copy(reader, client, head.length)
                await client.drain()

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


async def _copy(reader: asyncio.StreamReader, writer: asyncio.StreamWriter, length: int) -> None:
    """Copies ``length`` bytes of a frame's payload as they come."""
    left = length
    while left:
        block = await reader.read(min(COPY_BLOCK, left))
        if not block:
            raise asyncio.IncompleteReadError(b"", left)
        writer.write(block)
        left -= len(block)
        await writer.drain()
