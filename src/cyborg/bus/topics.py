"""Typed publishers and subscriptions: in-process, shared memory, or Zenoh with rmw_zenoh keys.

How a message travels depends on where its subscribers are:

* same :class:`~cyborg.bus.context.Context` (same process): handed over as a read-only sharing
  copy (:mod:`cyborg.bus.readonly`), never serialised;
* another process on this machine, for messages of ``SHM_THRESHOLD`` bytes or more: serialised
  once into a shared-memory slot (:mod:`cyborg.bus.shm`); only a slot reference travels, by
  Unix datagram (:mod:`cyborg.bus.doorbell`) or else through Zenoh;
* anyone else (other machines, ROS 2 nodes): CDR on the rmw_zenoh data key with the 33-byte
  attachment, so ``ros2 topic echo`` reads it.

A latched publisher (``Qos.latched()``, transient-local) keeps its last ``depth`` messages for
subscribers that join later, in-process and remote.

Whichever way a message came, its subscription's callback runs on the subscribing node's
callback thread (:mod:`cyborg.bus.executor`), never on the publisher's: a camera's thread does
not run a detector's inference, a tree's tick thread does not run a monitor's handling. Only a
subscription made with ``inline=True`` may be called on the publisher's thread, for an
in-process message arriving while its node is idle (see :class:`Subscription`). Both are
generic in their message class (``Publisher[String]``, :mod:`cyborg.bus.typed`).

Ownership: once published, a message belongs to the bus. In-process subscribers share its numpy
arrays read-only; write new arrays for the next message instead of filling the old ones.
"""

from __future__ import annotations

import threading
import time
from collections import deque
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, Generic

import zenoh
import zenoh.ext

from cyborg.bus.sequences import MAX_PUBLISHERS, SequenceTable
from cyborg.bus.shm import SlotReader, SlotRef, SlotRejectedError, SlotWriter
from cyborg.bus.typed import MessageT
from cyborg.bus.wire import (
    Attachment,
    Durability,
    EntityKind,
    History,
    Qos,
    Reliability,
    data_key,
    endpoint_token,
    fully_qualified,
    gid,
)

if TYPE_CHECKING:
    from cyborg.bus.node import Node

SHM_THRESHOLD = 64 * 1024
"""Messages of at least this many bytes go to local processes through shared memory."""

__all__ = ["MAX_PUBLISHERS", "SHM_THRESHOLD", "Publisher", "Subscription"]


class _Endpoint:
    """What publishers and subscriptions share: names, keys, the liveliness token, the GID."""

    def __init__(self, node: Node, topic: str, type_name: str, qos: Qos,
                 kind: EntityKind) -> None:
        context = node.context
        if type_name not in context.types:
            raise KeyError(f"{topic}: unknown message type {type_name!r}")
        self.node, self.context, self.qos = node, context, qos
        self.topic = fully_qualified(node.namespace, topic)
        self.type_name = type_name
        self.type_hash = context.types.hash(type_name)
        self.key = data_key(context.domain, self.topic, type_name, self.type_hash)
        self.entity_id = context.next_id()
        self.token_key = endpoint_token(
            context.domain, context.zid, node.id, self.entity_id, kind, node.namespace,
            node.name, self.topic, type_name, self.type_hash, qos)
        self.gid = gid(self.token_key)
        self._token: zenoh.LivelinessToken | None = None
        self._closed = False

    @property
    def closed(self) -> bool:
        """Whether this endpoint was destroyed (or its context closed under it)."""
        return self._closed

    def _announce(self) -> None:
        self._token = self.context.session.liveliness().declare_token(self.token_key)

    def _withdraw(self) -> bool:
        if self._closed or self.context.closed:
            self._closed = True
            return False
        self._closed = True
        if self._token is not None:
            self._token.undeclare()
        return True


class Publisher(_Endpoint, Generic[MessageT]):
    """Publishes messages of one type on one topic. Create with :meth:`Node.create_publisher`.

    ``Publisher[String]`` takes ``String`` messages only: mypy checks it, :meth:`publish` too.
    """

    def __init__(self, node: Node, topic: str, type_name: str, qos: Qos) -> None:
        super().__init__(node, topic, type_name, qos, EntityKind.PUBLISHER)
        # by name: the topic's type is whatever its creator gave (Node checked a class against
        # this one when it named it)
        self._class = self.context.types.message_class(type_name)
        self._sequence = 0
        self._graph_version, self._remote_count = -1, 0
        self._lock = threading.Lock()
        session = self.context.session
        reliability = (zenoh.Reliability.RELIABLE if qos.reliability is Reliability.RELIABLE
                       else zenoh.Reliability.BEST_EFFORT)
        block = qos.reliability is Reliability.RELIABLE and qos.history is History.KEEP_ALL
        congestion = zenoh.CongestionControl.BLOCK if block else zenoh.CongestionControl.DROP
        self.latched = qos.durability is Durability.TRANSIENT_LOCAL
        self._zenoh: zenoh.Publisher | zenoh.ext.AdvancedPublisher
        if self.latched:
            self._zenoh = zenoh.ext.declare_advanced_publisher(
                session, self.key, reliability=reliability, congestion_control=congestion,
                allowed_destination=zenoh.Locality.REMOTE,
                cache=zenoh.ext.CacheConfig(max_samples=max(qos.depth, 1)),
                publisher_detection=True)
        else:
            self._zenoh = session.declare_publisher(
                self.key, reliability=reliability, congestion_control=congestion,
                allowed_destination=zenoh.Locality.REMOTE)
        self._shm_publisher = session.declare_publisher(  # slot references: small, urgent
            self.context.shm_key(self.key), reliability=reliability, express=True,
            congestion_control=congestion, allowed_destination=zenoh.Locality.REMOTE)
        self._slots: SlotWriter | None = None
        self._announce()

    def publish(self, message: MessageT) -> None:
        """Send ``message`` to every subscriber, choosing the cheapest path for each.

        Those of this process get it queued to their nodes' threads (see
        :class:`Subscription`). Raises TypeError for a message of another class, RuntimeError
        once the publisher was destroyed.
        """
        if not isinstance(message, self._class):
            raise TypeError(f"publish on {self.topic}: expected {self.type_name}, "
                            f"got {type(message).__name__}")
        with self._lock:
            if self._closed:
                raise RuntimeError(f"publish on {self.topic}: the publisher was destroyed")
            self._sequence += 1
            attachment = Attachment(self._sequence, time.time_ns(), self.gid)
            if self.latched:
                self.context.latch(self.topic, self, (message, attachment))
            self._publish_remote(message, None, attachment.encode())
        for subscription in self.context.local_subscriptions(self.topic):
            subscription.deliver_local(message, self.type_name, attachment)

    def _publish_remote(self, message: Any, data: bytes | None, attachment: bytes) -> None:
        """Sends to other processes: ``message``, or its CDR ``data`` when already serialised."""
        context, types = self.context, self.context.types
        readers = () if self.latched else context.shm_readers(self.topic)
        if readers:
            size = types.cdr_size(message, self.type_name) if data is None else len(data)
            if size >= SHM_THRESHOLD:
                self._slots = self._slots or SlotWriter()
                ref = self._slots.write(size, lambda view: types.serialize_into(
                    message, self.type_name, view) if data is None else view.__setitem__(
                    slice(None), data))  # the slot's view is len(data) bytes
                if ref is not None:
                    reference, doorbell = ref.encode(), context.doorbell
                    if doorbell is None or not doorbell.ring(readers, attachment, reference):
                        self._shm_publisher.put(reference, attachment=attachment)
                    if self._remote_subscriptions() <= len(readers):
                        return
        if self.latched or self.matched():
            payload = types.serialize(message, self.type_name).obj if data is None else data
            self._zenoh.put(payload, attachment=attachment)

    def _remote_subscriptions(self) -> int:
        """Subscriptions of other sessions, counted again only when the graph has changed."""
        graph = self.context.graph
        version = graph.version  # read first: a change during the count makes the next recount
        if version != self._graph_version:
            self._remote_count = graph.count(self.topic, EntityKind.SUBSCRIPTION,
                                             exclude_zid=self.context.zid)
            self._graph_version = version
        return self._remote_count

    def matched(self) -> bool:
        """Whether Zenoh's routing matches a subscriber elsewhere (it may lag the graph)."""
        publisher = self._zenoh
        if not isinstance(publisher, zenoh.Publisher):
            return True
        status: Any = publisher.matching_status  # the stub says bool: a MatchingStatus
        return bool(status.matching)

    def subscription_count(self) -> int:
        """Subscriptions on this topic now: in this process plus elsewhere (from the graph)."""
        local = len(self.context.local_subscriptions(self.topic))
        remote = self.context.graph.count(self.topic, EntityKind.SUBSCRIPTION,
                                          exclude_zid=self.context.zid)
        return local + remote

    def destroy(self) -> None:
        """Withdraw the publisher from the bus (and its latched message); safe to call twice."""
        # under the lock: a publish on another thread (a node's callback, while the node is
        # being destroyed) may be using the Zenoh publishers, which cannot be undeclared then
        with self._lock:
            if not self._withdraw():
                return
            self.context.unlatch(self.topic, self)
            self._zenoh.undeclare()  # type: ignore[no-untyped-call]
            self._shm_publisher.undeclare()
            if self._slots is not None:
                self._slots.close()


class Subscription(_Endpoint, Generic[MessageT]):
    """Calls ``callback(message)`` on the node's thread for each message on a topic.

    It runs on the node's callback thread (or the one it was routed to:
    :meth:`~cyborg.bus.executor.CallbackThread.route`) wherever the message came from: never
    on the publisher's thread, never on Zenoh's.

    ``inline=True`` opts in to an optimisation for in-process messages: when the node is idle
    with nothing queued, the callback is called at once on the *publisher's* thread, saving
    the hand-over to the node's thread (a wake-up, and under load a wait for the interpreter
    lock). The node still runs one callback at a time and this subscription's messages keep
    their order, but the callback must not care which thread runs it and should be quick:
    the publisher waits for it.

    With ``with_info=True`` the callback is ``callback(message, info)``: ``info`` is the
    sample's :class:`~cyborg.bus.wire.Attachment` (publisher GID, sequence number, source
    timestamp), or None for a sample sent without one. Nothing authenticates it: the GID says
    which publisher a sample *claims* to come from.

    Up to ``qos.depth`` messages wait in the queue (keep-last: the oldest are dropped); with
    ``History.KEEP_ALL`` the queue is unbounded. Input that cannot be used (undecodable,
    malformed attachment, refused shared-memory slot) is dropped and counted in
    ``context.dropped``; duplicates are recognised by sequence number
    (:mod:`cyborg.bus.sequences`).
    """

    def __init__(self, node: Node, topic: str, type_name: str,
                 callback: Callable[..., object], qos: Qos, *, with_info: bool = False,
                 inline: bool = False) -> None:
        super().__init__(node, topic, type_name, qos, EntityKind.SUBSCRIPTION)
        self.callback = callback
        self.with_info = with_info
        self.inline = inline
        self.received = 0
        depth = None if qos.history is History.KEEP_ALL else max(qos.depth, 1)
        self._queue: deque[tuple[Any, Attachment | None]] = deque(maxlen=depth)
        self._scheduled = 0  # dispatches submitted to the node's thread, one per queued message
        self._last_sequence = SequenceTable()
        self._lock = threading.Lock()
        self._slots = SlotReader()
        session = self.context.session
        # Any type hash: ROS 2 Humble peers publish "TypeHashNotSupported" in its place.
        any_hash = data_key(self.context.domain, self.topic, type_name, "*")
        self._zenoh: Any
        if qos.durability is Durability.TRANSIENT_LOCAL:
            self._zenoh = zenoh.ext.declare_advanced_subscriber(
                session, any_hash, self._on_sample, allowed_origin=zenoh.Locality.REMOTE,
                history=zenoh.ext.HistoryConfig(detect_late_publishers=True,
                                                max_samples=max(qos.depth, 1)))
        else:
            self._zenoh = session.declare_subscriber(
                any_hash, self._on_sample, allowed_origin=zenoh.Locality.REMOTE)
        self._shm_subscriber = session.declare_subscriber(
            self.context.shm_key(self.key), self._on_slot, allowed_origin=zenoh.Locality.REMOTE)
        if self.context.doorbell is not None:
            self.context.doorbell.register(self.entity_id, self._on_reference)
        self._shm_token = session.liveliness().declare_token(
            self.context.shm_token(self.entity_id, self.topic))
        for _publisher, (message, attachment) in self.context.add_local(self.topic, self):
            self.deliver_local(message, type_name, attachment)
        self._announce()

    # ------------------------------------------------------------------ arrivals
    def deliver_local(self, message: Any, type_name: str, attachment: Attachment) -> None:
        """A message of this process (the publisher's thread): queue a read-only copy."""
        if type_name != self.type_name:
            self.context.drop(f"{self.topic}: type {type_name} instead of {self.type_name}")
            return
        if not self._last_sequence.record(attachment.gid, attachment.sequence):
            return
        copy = self.context.copier.copy(message, type_name)
        # Inline (opted in) only when nothing of this subscription is queued or about to run:
        # a dispatch taken off the node's queue but not yet running would come second.
        if self.inline and not self._scheduled and self.node.callbacks.try_inline(
                self._deliver_now, copy, attachment):
            return
        self._enqueue(copy, attachment)

    def _deliver_now(self, message: Any, info: Attachment | None) -> None:
        if not self._closed:
            self.received += 1
            if self.with_info:
                self.callback(message, info)
            else:
                self.callback(message)

    def _on_sample(self, sample: zenoh.Sample) -> None:
        """A CDR sample from Zenoh (a Zenoh thread)."""
        try:
            attachment = sample.attachment
            ok, info = self._parse(None if attachment is None else attachment.to_bytes())
            if ok and not self._seen(info):
                self._admit(self._decode(sample.payload.to_bytes()), info)
        except Exception as exc:  # a defect, not bad input: contain it, say it
            self._unexpected(exc)

    def _on_slot(self, sample: zenoh.Sample) -> None:
        """A shared-memory slot reference that came through Zenoh (a Zenoh thread)."""
        try:
            attachment = sample.attachment
            self._on_reference(None if attachment is None else attachment.to_bytes(),
                               sample.payload.to_bytes())
        except Exception as exc:
            self._unexpected(exc)

    def _on_reference(self, attachment: bytes | None, reference: bytes) -> None:
        """A slot reference, by Zenoh or by the doorbell: lease the slot, decode in place.

        Opening the slot never blocks: a reference to a FIFO, a link, another user's file or
        an oversized one is refused (:class:`~cyborg.bus.shm.SlotRejectedError`) and counted.
        """
        ok, info = self._parse(attachment)
        if not ok or self._seen(info):
            return
        try:
            ref = SlotRef.decode(reference)
        except ValueError as exc:
            self.context.drop(f"{self.topic}: bad slot reference", str(exc))
            return
        try:
            lease = self._slots.read(ref)
        except SlotRejectedError as exc:
            self.context.drop(f"{self.topic}: refused shared-memory slot", str(exc))
            return
        if lease is None:
            self.context.drop(f"{self.topic}: shared-memory slot reused before it was read")
            return
        self._admit(self._decode(lease.data), info)

    def _parse(self, attachment: bytes | None) -> tuple[bool, Attachment | None]:
        """(usable, attachment): not usable if malformed (counted); None if there is none."""
        if attachment is None:  # not rmw_zenoh, but harmless
            return True, None
        try:
            return True, Attachment.decode(attachment)
        except ValueError as exc:
            self.context.drop(f"{self.topic}: bad attachment", str(exc))
            return False, None

    def _seen(self, info: Attachment | None) -> bool:
        """A message already delivered (by another path): skip decoding it again."""
        return info is not None and self._last_sequence.seen(info.gid, info.sequence)

    def _admit(self, message: Any, info: Attachment | None) -> None:
        """Queue a decoded message, recording its sequence number only now that it is one."""
        if message is _UNDECODABLE:
            return
        if info is not None and not self._last_sequence.record(info.gid, info.sequence):
            return
        self._enqueue(message, info)

    def _decode(self, data: bytes | memoryview) -> Any:
        try:
            return self.context.types.deserialize(data, self.type_name)
        except Exception as exc:
            self.context.drop(f"{self.topic}: cannot decode {self.type_name}",
                              f"{type(exc).__name__}: {exc}")
            return _UNDECODABLE

    def _unexpected(self, exc: Exception) -> None:
        self.context.drop(f"{self.topic}: input handling failed",
                          f"{type(exc).__name__}: {exc}")

    def forget_publisher(self, gid: bytes) -> None:
        """Forget a publisher's sequence numbers (it left the graph)."""
        self._last_sequence.forget(gid)

    def _enqueue(self, message: Any, info: Attachment | None) -> None:
        # One dispatch per queued message, never more: when the keep-last queue is full a new
        # message replaces the oldest and needs no dispatch of its own, so a flood while the
        # node is busy grows neither this queue nor the node's.
        with self._lock:
            self._queue.append((message, info))
            if len(self._queue) <= self._scheduled:
                return
            self._scheduled += 1
        self.node.callbacks.submit(self._dispatch)

    def _dispatch(self) -> None:
        with self._lock:
            self._scheduled -= 1
            if not self._queue:
                return
            message, info = self._queue.popleft()
        self._deliver_now(message, info)

    def destroy(self) -> None:
        """Withdraw the subscription from the bus; messages still queued are not delivered."""
        if not self._withdraw():
            return
        self.context.remove_local(self.topic, self)
        if self.context.doorbell is not None:
            self.context.doorbell.unregister(self.entity_id)
        self._shm_token.undeclare()
        self._shm_subscriber.undeclare()
        self._zenoh.undeclare()
        self._slots.close()


_UNDECODABLE = object()

