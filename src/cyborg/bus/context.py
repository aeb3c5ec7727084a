"""One Zenoh session per process, shared by every node in it.

A :class:`Context` owns the session, the message types, the ROS graph (from liveliness tokens),
the table for in-process delivery, and the counters of dropped input. Nodes created in the same
context exchange messages in-process without serialising them; nodes in other contexts, other
processes or other machines are reached through Zenoh.

    with Context() as context:                 # joins the local router, if one runs
        talker = Node("talker", context=context)
        ...
"""

from __future__ import annotations

import atexit
import hashlib
import itertools
import logging
import os
import socket
import threading
import time
from collections import Counter
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any
from weakref import WeakSet

import zenoh

from cyborg.bus.config import BusConfig
from cyborg.bus.doorbell import Doorbell, supported
from cyborg.bus.graph import Graph, GraphEntity
from cyborg.bus.message_types import MessageTypes
from cyborg.bus.readonly import ReadonlyCopier
from cyborg.bus.wire import LIVELINESS_PREFIX, EntityKind, domain_id, gid

log = logging.getLogger("cyborg.bus")

SHM_PREFIX = "@cyborg_shm"
"""Liveliness tokens and keys of subscriptions that take large messages through shared memory."""

DROP_REPORT_INTERVAL = 60.0
"""Wall seconds between two warnings about dropped input of the same kind (the first is said
at once; later ones are counted and summed up at most this often)."""


_OPEN: WeakSet[Context] = WeakSet()


def _close_open_contexts() -> None:
    for context in list(_OPEN):
        context.close()


# Zenoh keeps non-daemon threads while a session is open, and Python joins those before it runs
# atexit handlers; so open sessions are closed from the hook that runs before that join.
getattr(threading, "_register_atexit", atexit.register)(_close_open_contexts)


def host_id() -> str:
    """A 16-hex-digit hash that identifies this machine (and boot) and user.

    Shared memory is only offered to local peers of the same user: slot files are private to
    their owner (mode 0600), and a reader refuses other users' files.
    """
    boot = Path("/proc/sys/kernel/random/boot_id")
    text = socket.gethostname() + (boot.read_text().strip() if boot.exists() else "") + \
        f"/uid{os.geteuid()}"
    return hashlib.blake2b(text.encode(), digest_size=8).hexdigest()


class Context:
    """A process's connection to the bus. Close it (or use ``with``) to leave cleanly.

    ``config`` says how to connect (default :meth:`BusConfig.from_environment`), ``types`` holds
    the message types (default a fresh :class:`MessageTypes`), and ``domain`` is the ROS domain
    (default from ``ROS_DOMAIN_ID``, :func:`~cyborg.bus.wire.domain_id`).
    """

    def __init__(self, config: BusConfig | None = None, *, types: MessageTypes | None = None,
                 domain: int | None = None) -> None:
        self.config = config if config is not None else BusConfig.from_environment()
        self.types = types if types is not None else MessageTypes()
        self.copier = ReadonlyCopier(self.types)
        self.domain = domain_id() if domain is None else domain
        self.host = host_id()
        self.session = zenoh.open(self.config.to_zenoh())
        self.zid = str(self.session.zid())
        self.graph = Graph(self.domain)
        self.graph.on_departure(self._on_departure)
        self.dropped: Counter[str] = Counter()
        """Input dropped, by reason: ``'/topic: cannot decode'``, ``'/topic: slot reused'``."""
        self._ids = itertools.count(0)
        self._lock = threading.Lock()
        self._local: dict[str, list[Any]] = {}
        self._latched: dict[str, list[Any]] = {}
        self._shm_readers: dict[str, set[tuple[str, int]]] = {}
        self._nodes: list[Any] = []
        self._reported: dict[str, tuple[float, int]] = {}  # reason -> (when said, count then)
        self._closed = False
        self.calls = ThreadPoolExecutor(max_workers=8, thread_name_prefix="cyborg-call")
        self.doorbell = self._open_doorbell()
        _OPEN.add(self)  # closed at exit if the program forgets to
        liveliness = self.session.liveliness()
        self._graph_sub = liveliness.declare_subscriber(
            f"{LIVELINESS_PREFIX}/{self.domain}/**", self._on_token, history=True)
        self._shm_sub = liveliness.declare_subscriber(
            f"{SHM_PREFIX}/{self.domain}/{self.host}/**", self._on_shm_token, history=True)

    # ------------------------------------------------------------------ identity
    def next_id(self) -> int:
        """A fresh node or entity id, unique in this session."""
        with self._lock:
            return next(self._ids)

    def _open_doorbell(self) -> Doorbell | None:
        if not (self.config.doorbell and supported()):
            return None
        try:
            return Doorbell(self.domain, self.zid, self.drop)
        except OSError as exc:  # slot references then travel through Zenoh
            log.warning("no doorbell for shared-memory references (%s)", exc)
            return None

    # ------------------------------------------------------------------ graph feed
    def _on_token(self, sample: zenoh.Sample) -> None:
        key = str(sample.key_expr)
        if sample.kind == zenoh.SampleKind.PUT:
            self.graph.add(key)
        else:
            self.graph.remove(key)

    def _on_departure(self, entity: GraphEntity) -> None:
        """An endpoint left the graph: a publisher's sequence numbers are no longer needed."""
        if entity.kind is EntityKind.PUBLISHER:
            publisher = gid(entity.key)
            for subscription in self.local_subscriptions(entity.topic):
                subscription.forget_publisher(publisher)

    def _on_shm_token(self, sample: zenoh.Sample) -> None:
        # @cyborg_shm/<domain>/<host>/<zid>/<eid>/<mangled topic>
        chunks = str(sample.key_expr).split("/")
        if len(chunks) != 6 or not chunks[4].isdigit() or len(chunks[4]) > 10:
            return
        topic, reader = chunks[5].replace("%", "/"), (chunks[3], int(chunks[4]))
        with self._lock:
            if sample.kind == zenoh.SampleKind.PUT:
                self._shm_readers.setdefault(topic, set()).add(reader)
                return
            readers = self._shm_readers.get(topic)
            if readers is not None:
                readers.discard(reader)
                if not readers:  # keyed by names others choose: keep no empty entries
                    del self._shm_readers[topic]

    def shm_readers(self, topic: str) -> tuple[tuple[str, int], ...]:
        """The subscriptions of other local sessions that take ``topic`` through shared memory.

        Each is a (session id, entity id) pair; sessions of other users or machines never count.
        """
        with self._lock:
            return tuple(r for r in self._shm_readers.get(topic, ()) if r[0] != self.zid)

    def shm_reader_count(self, topic: str) -> int:
        """How many :meth:`shm_readers` ``topic`` has."""
        return len(self.shm_readers(topic))

    def shm_token(self, entity_id: int, topic: str) -> str:
        """The liveliness key by which subscription ``entity_id`` takes ``topic`` through shm.

        Publishers on this machine find it through :meth:`shm_readers` and send that
        subscription large messages as slot references.
        """
        return f"{SHM_PREFIX}/{self.domain}/{self.host}/{self.zid}/{entity_id}/" + \
            topic.replace("/", "%")

    def shm_key(self, data_key: str) -> str:
        """The key on which slot references of ``data_key`` travel, on this machine only."""
        return f"{SHM_PREFIX}/{self.host}/{data_key}"

    # ------------------------------------------------------------------ in-process delivery
    def add_local(self, topic: str, subscription: Any) -> list[Any]:
        """Register an in-process subscription; returns the latched messages it should get."""
        with self._lock:
            self._local.setdefault(topic, []).append(subscription)
            return list(self._latched.get(topic, ()))

    def remove_local(self, topic: str, subscription: Any) -> None:
        """Unregister an in-process subscription; nothing happens if it is not registered."""
        with self._lock:
            subscribers = self._local.get(topic, [])
            if subscription in subscribers:
                subscribers.remove(subscription)
            if not subscribers:
                self._local.pop(topic, None)

    def local_subscriptions(self, topic: str) -> tuple[Any, ...]:
        """The in-process subscriptions on ``topic`` now, as a snapshot safe to iterate."""
        with self._lock:
            return tuple(self._local.get(topic, ()))

    def latch(self, topic: str, publisher: Any, delivery: Any) -> None:
        """Remember the last message of a latched publisher for late in-process subscribers."""
        with self._lock:
            entries = [d for d in self._latched.get(topic, []) if d[0] is not publisher]
            self._latched[topic] = [*entries, (publisher, delivery)]

    def unlatch(self, topic: str, publisher: Any) -> None:
        """Forget the last message of ``publisher`` on ``topic`` (it is being destroyed)."""
        with self._lock:
            entries = [d for d in self._latched.get(topic, []) if d[0] is not publisher]
            if entries:
                self._latched[topic] = entries
            else:
                self._latched.pop(topic, None)

    # ------------------------------------------------------------------ dropped input
    def drop(self, reason: str, detail: str = "") -> None:
        """Count one dropped input in :attr:`dropped`, and log it.

        The first drop of each kind is logged at once, later ones at most once every
        ``DROP_REPORT_INTERVAL`` seconds with the number dropped since. ``reason`` names where
        (the topic or service) and what; ``detail`` says why. Safe to call from any thread.
        """
        now = time.monotonic()
        with self._lock:
            self.dropped[reason] += 1
            count = self.dropped[reason]
            said = self._reported.get(reason)
            if said is not None and now - said[0] < DROP_REPORT_INTERVAL:
                return
            self._reported[reason] = (now, count)
        suffix = f": {detail}" if detail else ""
        if said is None:
            log.warning("dropped input (%s)%s; further drops of this kind are counted",
                        reason, suffix)
        else:
            log.warning("dropped input (%s) %d more times in %.0f s; the last%s", reason,
                        count - said[1], now - said[0], suffix or " without detail")

    # ------------------------------------------------------------------ lifetime
    def register_node(self, node: Any) -> None:
        """Keep ``node`` to be destroyed by :meth:`close`; each node calls it when created."""
        with self._lock:
            self._nodes.append(node)

    def forget_node(self, node: Any) -> None:
        """Stop keeping ``node`` (destroyed on its own); nothing happens if it is unknown."""
        with self._lock:
            if node in self._nodes:
                self._nodes.remove(node)

    @property
    def closed(self) -> bool:
        """Whether :meth:`close` has run: its nodes are destroyed and its session is closed."""
        return self._closed

    def close(self) -> None:
        """Destroy every node, then close the session. Safe to call twice."""
        if self._closed:
            return
        for node in list(self._nodes):
            node.destroy()
        self._closed = True
        _OPEN.discard(self)
        self.calls.shutdown(wait=False, cancel_futures=True)
        for declared in (self._graph_sub, self._shm_sub):
            declared.undeclare()
        if self.doorbell is not None:
            self.doorbell.close()
        self.session.close()

    def __enter__(self) -> Context:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
