"""Raw endpoints: a topic's messages as the CDR bytes they travel in, never decoded again.

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
:attr:`RawSubscription.backlog_peak` is the most messages that ever waited in its queue at
once, so a recorder can tell how close its writer came to dropping (a full keep-last queue
drops the oldest). Create one with :meth:`cyborg.bus.node.Node.create_raw_subscription`.

A *batched* raw subscription (``batched=True``) does not wake its node for each message:
messages wait in its queue (keep-last, ``qos.depth``) until the node calls
:meth:`RawSubscription.drain`, which hands every waiting message to the callback at once. A
recorder drains its topics a few times a second from a timer, so hundreds of small messages a
second cost a few thread wake-ups instead of one each (a wake-up, and the hand-over of the
interpreter lock, cost more than writing a small message down).

A player wants the reverse: to send what a recording holds as it was recorded. A
:class:`RawPublisher` is a :class:`~cyborg.bus.topics.Publisher` (same keys, token, QoS,
latching, shared memory) whose :meth:`RawPublisher.publish_raw` takes CDR bytes (with their
encapsulation header) and sends them to other processes as they are. Subscriptions of this
process, which take messages, get the bytes decoded once (so does a latched publisher's
history, which later subscriptions of this process are handed). Create one with
:meth:`cyborg.bus.node.Node.create_raw_publisher`.
"""

from __future__ import annotations

import time
from typing import Any, NamedTuple

from cyborg.bus.topics import Publisher, Subscription
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

    backlog_peak = 0
    """The most messages that waited in this subscription's queue at once."""

    def __init__(self, *args: Any, batched: bool = False, **options: Any) -> None:
        self.batched = batched  # before the base queues a latched publisher's history
        super().__init__(*args, **options)

    def deliver_local(self, message: Any, type_name: str, attachment: Attachment) -> None:
        """A message of this process: queue it as it is, to be serialised when delivered."""
        if type_name != self.type_name:
            self.context.drop(f"{self.topic}: type {type_name} instead of {self.type_name}")
            return
        if not self._last_sequence.record(attachment.gid, attachment.sequence):
            return
        self._enqueue(_Local(message, time.time_ns()), attachment)

    def _enqueue(self, message: Any, info: Attachment | None) -> None:
        if self.batched:
            with self._lock:  # waits for drain(): no dispatch to the node's thread
                self._queue.append((message, info))
        else:
            super()._enqueue(message, info)
        backlog = len(self._queue)  # a deque's length is read atomically
        if backlog > self.backlog_peak:
            self.backlog_peak = backlog

    def drain(self) -> int:
        """Hands every waiting message to the callback now, oldest first; returns how many.

        For a batched subscription, on the node's thread (a timer's callback); a subscription
        that is not batched has nothing waiting for this.
        """
        with self._lock:
            waiting = list(self._queue)
            self._queue.clear()
        for message, info in waiting:
            self._deliver_now(message, info)
        return len(waiting)

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


class RawPublisher(Publisher[Any]):
    """Publishes CDR bytes on a topic as they are; see the module.

    Made by :meth:`~cyborg.bus.node.Node.create_raw_publisher`. The type name must be known to
    the bus (it makes the key and the token, and decodes for subscriptions of this process).
    """

    def publish_raw(self, data: bytes) -> None:
        """Sends ``data`` (CDR with its encapsulation header) to every subscriber.

        Raises RuntimeError once the publisher was destroyed; for a latched publisher or one
        with subscriptions in this process, whatever decoding ``data`` raises (bytes that are
        not a message of the type).
        """
        local = self.context.local_subscriptions(self.topic)
        message = (self.context.types.deserialize(data, self.type_name)
                   if local or self.latched else None)
        with self._lock:
            if self._closed:
                raise RuntimeError(f"publish on {self.topic}: the publisher was destroyed")
            self._sequence += 1
            attachment = Attachment(self._sequence, time.time_ns(), self.gid)
            if self.latched:
                self.context.latch(self.topic, self, (message, attachment))
            self._publish_remote(message, data, attachment.encode())
        for subscription in local:
            subscription.deliver_local(message, self.type_name, attachment)
