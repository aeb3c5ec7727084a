"""Raw subscriptions: a topic's messages as the CDR bytes they travel in, never decoded.

A recorder wants what went over the wire, not Python objects: ``ros2 bag`` stores the
serialized message as it arrived, and so does ``cyborg record``. A :class:`RawSubscription`
is a :class:`~cyborg.bus.topics.Subscription` in every other respect — the same keys and
liveliness token (it shows in the graph as a subscription of its type), the same QoS and
latched history, shared memory, duplicate detection and callback thread — but hands its
callback a :class:`RawMessage`:

* from another process or machine, the sample's payload as it came (CDR with its 4-byte
  encapsulation header), copied out of the shared-memory slot when it came that way;
* from this process, where messages are never serialised, the CDR the publisher would have
  sent to another process (serialised on the subscribing node's thread, not the publisher's).

``received_ns`` is the wall-clock time (ns since the epoch) at which the bus received the
message, before it waited in the queue; ``info`` is the sample's attachment (publisher GID,
sequence number and the publisher's own timestamp), or None for a sample sent without one.
Create one with :meth:`cyborg.bus.node.Node.create_raw_subscription`.
"""

from __future__ import annotations

import time
from typing import Any, NamedTuple

from cyborg.bus.topics import Subscription
from cyborg.bus.wire import Attachment


class RawMessage(NamedTuple):
    """One message as it travelled: CDR bytes, when the bus got it, and its attachment."""

    data: bytes
    """The serialized message: CDR with its encapsulation header, as on the wire."""
    received_ns: int
    """Wall-clock time the bus received it, ns since the epoch."""
    info: Attachment | None
    """The sample's attachment (sender's timestamp, sequence, GID), if it carried one."""


class _Local(NamedTuple):
    """A message of this process, waiting to be serialised on the subscriber's thread."""

    message: Any
    received_ns: int


class RawSubscription(Subscription[RawMessage]):
    """Calls ``callback(RawMessage)`` for each message on a topic, without decoding it.

    Made by :meth:`~cyborg.bus.node.Node.create_raw_subscription`; see the module for what
    the bytes are. The type name must be known to the bus (it makes the key and the token).
    """

    def deliver_local(self, message: Any, type_name: str, attachment: Attachment) -> None:
        """A message of this process: queue it as it is, to be serialised when delivered."""
        if type_name != self.type_name:
            self.context.drop(f"{self.topic}: type {type_name} instead of {self.type_name}")
            return
        if not self._last_sequence.record(attachment.gid, attachment.sequence):
            return
        self._enqueue(_Local(message, time.time_ns()), attachment)

    def _decode(self, data: bytes | memoryview) -> Any:
        """The payload itself (copied out of a shared-memory slot), stamped on arrival."""
        return bytes(data), time.time_ns()

    def _deliver_now(self, message: Any, info: Attachment | None) -> None:
        if self._closed:
            return
        if isinstance(message, _Local):
            data = bytes(self.context.types.serialize(message.message, self.type_name))
            raw = RawMessage(data, message.received_ns, info)
        else:
            raw = RawMessage(message[0], message[1], info)
        self.received += 1
        self.callback(raw)
