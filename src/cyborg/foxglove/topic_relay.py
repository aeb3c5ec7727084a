"""A ROS 2 topic passed through to Foxglove: its ``ros2msg`` schema and its CDR bytes as they came.

The channel has the topic's name, its type's full definition as schema and ``cdr`` encoding;
each message is forwarded as the bytes that travelled on the bus (a raw subscription,
:meth:`cyborg.bus.Node.create_subscription`), never decoded or encoded again, with the time it
arrived as its log time. A latched topic's last message from each publisher is kept while the
relay is open and sent again to each client that subscribes later.
"""

from __future__ import annotations

import threading
import time

import foxglove

from cyborg.bus import Node, Qos
from cyborg.bus.raw import RawMessage, RawSubscription
from cyborg.foxglove.relay import Relay
from cyborg.foxglove.schemas import CDR, ros2msg_schema

DEPTH = 10
"""Messages a subscription queues for the bridge's thread before the oldest are dropped."""
LATCHED_DEPTH = 10
"""Latched messages kept per topic (one per publisher, as ``/tf_static`` has several)."""


class TopicRelay(Relay):
    """Relays ``topic`` of ``type_name`` through ``node``; ``latched`` as its publishers say.

    The channel is created on ``context`` (the Foxglove server's).
    """

    def __init__(self, node: Node, topic: str, type_name: str, *, latched: bool,
                 context: foxglove.Context) -> None:
        super().__init__(topic)
        self.node, self.type_name, self.latched = node, type_name, latched
        self.channel: foxglove.Channel = foxglove.Channel(
            topic, schema=ros2msg_schema(node.types, type_name), message_encoding=CDR,
            context=context, metadata={"latched": "true" if latched else "false"})
        self.forwarded = 0
        """Messages passed to Foxglove so far."""
        self._lock = threading.Lock()
        self._subscription: RawSubscription | None = None
        self._kept: dict[bytes, bytes] = {}  # publisher GID -> its last latched message

    def open(self) -> None:
        """Subscribe on the bus (latched if the topic is), raw."""
        with self._lock:
            if self._subscription is not None:
                return
            qos = Qos.latched(LATCHED_DEPTH) if self.latched else Qos(depth=DEPTH)
            self._subscription = self.node.create_raw_subscription(
                self.topic, self.type_name, self._on_message, qos)

    def close(self) -> None:
        """Leave the bus and forget the kept messages."""
        with self._lock:
            subscription, self._subscription = self._subscription, None
            self._kept.clear()
        if subscription is not None:
            subscription.destroy()

    def replay(self) -> None:
        """Send the kept latched messages again (a client subscribed after they came)."""
        with self._lock:
            kept = list(self._kept.values())
        for data in kept:
            self.channel.log(data, log_time=time.time_ns())

    def _on_message(self, message: RawMessage) -> None:
        data, info = message.data, message.info
        if self.latched:
            with self._lock:
                if self._subscription is None:
                    return
                gid = info.gid if info is not None else b""
                self._kept.pop(gid, None)  # newest last, and bounded
                self._kept[gid] = data
                while len(self._kept) > LATCHED_DEPTH:
                    self._kept.pop(next(iter(self._kept)))
        self.channel.log(data, log_time=time.time_ns())
        self.forwarded += 1
