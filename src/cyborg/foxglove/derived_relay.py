"""Relays that read bus messages and write something else for Foxglove (a grid, a scene, JSON).

A :class:`DerivedRelay` subscribes, while watched, to topics of cyborg's contracts
(:mod:`cyborg.interfaces`) under one namespace, decoded as the contracts' classes, and turns
each message into what its channel carries (:meth:`DerivedRelay.convert`). The work runs on a
callback thread of its own (``thread``), so drawing a large map never delays the topics passed
through on the bridge's node. What it made last from a latched topic is kept and sent again to
a client that subscribes later. A message it cannot convert is logged (once per relay and
reason) and skipped.
"""

from __future__ import annotations

import logging
import threading
import time
from abc import abstractmethod
from functools import partial
from typing import Any

from cyborg.bus import Node, Subscription
from cyborg.bus.executor import CallbackThread
from cyborg.foxglove.relay import Relay
from cyborg.interfaces.contract import Topic

log = logging.getLogger("cyborg.foxglove")

SAID_REASONS = 100
"""Distinct reasons for skipping a message that a relay logs; later ones are skipped quietly."""


class DerivedRelay(Relay):
    """A relay fed by ``sources`` (contract topics under ``namespace``) through ``node``.

    Messages of every source go to :meth:`convert`; a non-None result is written with
    :meth:`write`. Results made from a latched source are kept for :meth:`replay`.
    """

    def __init__(self, topic: str, node: Node, namespace: str, sources: tuple[Topic[Any], ...],
                 thread: CallbackThread) -> None:
        super().__init__(topic)
        self.node, self.namespace, self.sources, self.thread = node, namespace, sources, thread
        self.written = 0
        """Messages written to the channel so far."""
        self._lock = threading.Lock()
        self._subscriptions: list[Subscription[Any]] = []
        self._kept: Any = None
        self._refused: set[str] = set()

    def open(self) -> None:
        """Subscribe to the sources, on the relay's callback thread."""
        with self._lock:
            if self._subscriptions:
                return
            for source in self.sources:
                subscription = source.subscription(
                    self.node, partial(self._on_message, source), self.namespace)
                self.node.callbacks.route(subscription, self.thread)
                self._subscriptions.append(subscription)

    def close(self) -> None:
        """Leave the bus and forget what was kept."""
        with self._lock:
            subscriptions, self._subscriptions = self._subscriptions, []
            self._kept = None
        for subscription in subscriptions:
            subscription.destroy()
            self.node.callbacks.unroute(subscription)

    def replay(self) -> None:
        """Write again what was made from the latched source last."""
        with self._lock:
            kept = self._kept
        if kept is not None:
            self.write(kept, time.time_ns())

    def _on_message(self, source: Topic[Any], message: Any) -> None:
        try:
            result = self.convert(source, message)
        except ValueError as exc:
            if str(exc) not in self._refused and len(self._refused) < SAID_REASONS:
                self._refused.add(str(exc))
                log.warning("%s: %s skipped: %s", self.topic, source.full_name(self.namespace),
                            exc)
            return
        if result is None:
            return
        with self._lock:
            if not self._subscriptions:
                return
            if source.latched:
                self._kept = result
        self.write(result, time.time_ns())
        self.written += 1

    @abstractmethod
    def convert(self, source: Topic[Any], message: Any) -> Any:
        """What to write for ``message`` of ``source``; None: nothing (ValueError: refused)."""

    @abstractmethod
    def write(self, result: Any, log_time: int) -> None:
        """Write one result to the channel."""
