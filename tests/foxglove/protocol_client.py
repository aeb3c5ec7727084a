"""A plain client of the Foxglove WebSocket protocol, written from the protocol, for the tests.

It speaks what the Foxglove app speaks, with no SDK: it opens a WebSocket with the subprotocol
``foxglove.websocket.v1`` (or ``foxglove.sdk.v1``), reads the server's JSON ``serverInfo``,
``advertise`` and ``unadvertise`` messages, sends ``subscribe`` and ``unsubscribe``, and reads
binary message data: opcode ``0x01``, the subscription id (u32 LE), the log time in
nanoseconds (u64 LE), then the payload.
"""

from __future__ import annotations

import contextlib
import json
import struct
import time
from collections.abc import Callable
from typing import Any

from websockets.sync.client import ClientConnection, connect
from websockets.typing import Subprotocol

MESSAGE_DATA = 0x01
_HEADER = struct.Struct("<BIQ")


class ProtocolClient:
    """One connection; channels advertised so far by topic, messages by subscription id."""

    def __init__(self, url: str, subprotocol: str = "foxglove.websocket.v1",
                 headers: dict[str, str] | None = None) -> None:
        self._stack = contextlib.ExitStack()
        self.connection: ClientConnection = self._stack.enter_context(connect(
            url, subprotocols=[Subprotocol(subprotocol)], additional_headers=headers,
            open_timeout=20, max_size=None))
        self.server_info: dict[str, Any] | None = None
        self.channels: dict[str, dict[str, Any]] = {}
        self.messages: dict[int, list[tuple[int, bytes]]] = {}
        self._next_id = 1
        self.statuses: list[dict[str, Any]] = []

    def close(self) -> None:
        self._stack.close()

    def __enter__(self) -> ProtocolClient:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def read(self, timeout: float) -> bool:
        """Take one message from the server, if one comes within ``timeout`` seconds."""
        try:
            frame = self.connection.recv(timeout=timeout)
        except TimeoutError:
            return False
        if isinstance(frame, bytes):
            opcode, subscription, log_time = _HEADER.unpack_from(frame)
            assert opcode == MESSAGE_DATA, f"unexpected binary opcode {opcode}"
            self.messages.setdefault(subscription, []).append((log_time,
                                                               frame[_HEADER.size:]))
            return True
        message = json.loads(frame)
        if message["op"] == "serverInfo":
            self.server_info = message
        elif message["op"] == "advertise":
            for channel in message["channels"]:
                self.channels[channel["topic"]] = channel
        elif message["op"] == "status":
            self.statuses.append(message)
        elif message["op"] == "unadvertise":
            gone = set(message["channelIds"])
            self.channels = {topic: channel for topic, channel in self.channels.items()
                             if channel["id"] not in gone}
        return True

    def until(self, condition: Callable[[], object], timeout: float = 30.0) -> bool:
        """Read messages until ``condition()`` holds or ``timeout`` seconds pass."""
        deadline = time.monotonic() + timeout
        while not condition():
            left = deadline - time.monotonic()
            if left <= 0:
                return False
            self.read(min(left, 0.2))
        return True

    def channel(self, topic: str, timeout: float = 30.0) -> dict[str, Any]:
        """The channel advertised for ``topic``, waiting for it."""
        assert self.until(lambda: topic in self.channels, timeout), \
            f"{topic} not advertised; channels: {sorted(self.channels)}"
        return self.channels[topic]

    def subscribe(self, topic: str) -> int:
        """Subscribe to the channel of ``topic``; returns the subscription id."""
        subscription = self._next_id
        self._next_id += 1
        channel = self.channel(topic)["id"]
        self._send_subscribe(subscription, channel)
        return subscription

    def _send_subscribe(self, subscription: int, channel: int) -> None:
        self.connection.send(json.dumps({"op": "subscribe", "subscriptions": [
            {"id": subscription, "channelId": channel}]}))

    def unsubscribe(self, subscription: int) -> None:
        self.connection.send(json.dumps({"op": "unsubscribe",
                                         "subscriptionIds": [subscription]}))

    def payloads(self, subscription: int, count: int = 1, timeout: float = 30.0) -> list[bytes]:
        """The first ``count`` payloads of ``subscription``, waiting for them."""
        assert self.until(lambda: len(self.messages.get(subscription, [])) >= count, timeout), \
            f"subscription {subscription}: {len(self.messages.get(subscription, []))} messages"
        return [payload for _, payload in self.messages[subscription][:count]]
