"""The tree runner's ``services`` topic: the states of the services on its composites.

A :class:`ServiceStatesPublisher` is offered the service states of the tree that ticks
(:meth:`ServiceRunner.states <cyborg.bt.service_runner.ServiceRunner.states>`, ``None`` for a
tree without services) after every tick (the snapshot's) and every run or halt of services
outside a tick (read under the tick loop's lock). ``states()`` hands back the very same tuple
while nothing changed, so an offer of unchanged states costs one identity test; a changed one
is published on :data:`~cyborg.interfaces.tree_runner.SERVICE_STATES` (latched), at most
:data:`~cyborg.interfaces.tree_runner.SERVICE_STATES_PER_SECOND` times a second of wall time:
states offered sooner wait, and the newest of them goes out when the interval has passed (from
a timer thread), so the last change is never lost.

A tree without services publishes nothing. When the tree that ticks changes (a reload, a mode
switch) to one without services after one with them, a message with no services says so once.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Sequence

from cyborg.bt.service_runner import ServiceState
from cyborg.bt.snapshot import TickSnapshot
from cyborg.bt.tree import Tree
from cyborg.bus import Node
from cyborg.bus.msgs.builtin_interfaces.msg import Time
from cyborg.bus.msgs.cyborg_msgs.msg import ServiceState as ServiceStateMessage
from cyborg.bus.msgs.cyborg_msgs.msg import ServiceStates
from cyborg.bus.msgs.diagnostic_msgs.msg import KeyValue
from cyborg.interfaces import tree_runner


def stamp_of(seconds: float) -> Time:
    """``seconds`` on the tree's clock as a ``builtin_interfaces/Time`` (to the nanosecond)."""
    whole = int(seconds // 1)
    return Time(sec=whole, nanosec=min(round((seconds - whole) * 1e9), 999_999_999))


def states_message(tree_id: str, states: Sequence[ServiceState], now: float) -> ServiceStates:
    """The ``cyborg_msgs/ServiceStates`` of ``states``, taken at ``now`` on the tree's clock."""
    return ServiceStates(stamp=stamp_of(now), tree_id=tree_id, services=[
        ServiceStateMessage(
            composite=state.composite, service=state.service, active=state.active,
            runs=state.runs,
            last_run=stamp_of(state.last_run if state.last_run is not None else 0.0),
            wrote=[KeyValue(key=key, value=value) for key, value in state.wrote.items()],
            error=state.error or "")
        for state in states])


def states_of(tree: Tree) -> tuple[ServiceState, ...] | None:
    """The states of ``tree``'s services now; ``None`` for a tree without services."""
    services = tree.services
    return None if services is None else services.states()


class ServiceStatesPublisher:
    """Publishes the service states offered to it; see the module docstring."""

    def __init__(self, node: Node, *,
                 per_second: float = tree_runner.SERVICE_STATES_PER_SECOND) -> None:
        self._publisher = tree_runner.SERVICE_STATES.publisher(node)
        self.interval = 1.0 / per_second
        """Shortest wall time between two messages, in seconds."""
        self._lock = threading.Lock()
        self._offered: tuple[ServiceState, ...] | None = None
        self._pending: ServiceStates | None = None
        self._timer: threading.Timer | None = None
        self._sent_at = -float("inf")
        self._showing = False
        """Whether the last message queued listed services."""
        self._closed = False
        self._looked: tuple[Tree | None, int] = (None, 0)
        """The tree last looked at outside a tick, and its tick count then."""
        self.published = 0
        """How many messages it has published."""

    def tick_ended(self, tree: Tree, snapshot: TickSnapshot) -> None:
        """After a tick: the states its snapshot took, unless it switched to ``tree`` (a mode).

        A snapshot older than a :meth:`look` at the same tree is passed over: a halt on another
        thread (a disable) may have stopped the services after the tick and before this.
        """
        if tree is self._looked[0] and snapshot.tick <= self._looked[1]:
            return
        self.offer(tree, snapshot.services if tree.last is snapshot else states_of(tree))

    def look(self, tree: Tree) -> None:
        """The states of ``tree`` read now: under the tick loop's lock, or while no tick runs."""
        self._looked = (tree, tree.ticks)
        self.offer(tree, states_of(tree))

    def offer(self, tree: Tree, states: tuple[ServiceState, ...] | None) -> None:
        """The service ``states`` of ``tree``, the tree that ticks now (``None``: it has none).

        Cheap when they are the very states offered last (nothing changed); may be called
        from the ticking thread and from a thread that halted the tree.
        """
        if states is self._offered:
            return
        with self._lock:
            if self._closed or states is self._offered:
                return
            self._offered = states
            if not states and not self._showing:
                return  # a tree without services, and none shown before it
            self._showing = bool(states)
            self._pending = states_message(tree.tree_id, states or (), tree.clock.now())
            wait = self._sent_at + self.interval - time.monotonic()
            if wait <= 0:
                self._send_pending()
            elif self._timer is None:
                self._timer = threading.Timer(wait, self._flush)
                self._timer.daemon = True
                self._timer.name = "cyborg-service-states"
                self._timer.start()

    def _flush(self) -> None:
        with self._lock:
            self._timer = None
            if not self._closed:
                self._send_pending()

    def _send_pending(self) -> None:
        """Publishes the pending message (under the lock)."""
        message, self._pending = self._pending, None
        if message is None:
            return
        self._sent_at = time.monotonic()
        self._publisher.publish(message)
        self.published += 1

    def close(self) -> None:
        """Drops what is pending and publishes nothing more (the runner is going)."""
        with self._lock:
            self._closed = True
            self._pending = None
            if self._timer is not None:
                self._timer.cancel()
                self._timer = None
