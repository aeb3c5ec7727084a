"""Relays: Foxglove channels fed from the bus, which subscribe on the bus only while watched.

A :class:`Relay` owns one Foxglove channel (a ROS 2 topic passed through, a robot's map drawn
for Foxglove, a tree's ticks as JSON). It subscribes on the bus when the first Foxglove client
subscribes to its channel (:meth:`Relay.open`) and leaves the bus when the last one goes
(:meth:`Relay.close`) and :data:`LINGER` seconds have passed with nobody watching, so a camera's
images cost nothing while nobody watches them, and a client that comes back (a reconnect, a
panel switched off and on) finds the relay still open: subscribing and leaving the bus again
for every connection would cost each time (a latched topic fetched and drawn again, and the
bus's middleware keeps a little of every subscription it ever declared). A client that
subscribes while the relay is open is sent what it keeps of latched topics
(:meth:`Relay.replay`): it would otherwise wait for the next change of a map published once.

:class:`Relays` holds the relays by channel id and is the Foxglove server's listener: the server
calls it (on its own threads) as clients subscribe and unsubscribe.
"""

from __future__ import annotations

import logging
import threading
import time
from abc import ABC, abstractmethod
from collections.abc import Callable
from typing import Any, Protocol

from foxglove.websocket import ChannelView, Client, ServerListener

log = logging.getLogger("cyborg.foxglove")

LINGER = 10.0
"""Seconds a relay stays on the bus after its last client left (0: it leaves at once)."""


class Channel(Protocol):
    """What a relay needs of a Foxglove channel (``foxglove.Channel`` or a typed one)."""

    def id(self) -> int:
        """The channel's id on the server."""
        ...

    def close(self) -> None:
        """Unadvertise the channel."""
        ...


class Relay(ABC):
    """One Foxglove channel, fed from the bus while at least one client watches it.

    Subclasses make :attr:`channel` and implement :meth:`open` and :meth:`close`.
    """

    channel: Channel

    def __init__(self, topic: str) -> None:
        self.topic = topic
        """The channel's topic, as Foxglove shows it."""

    @property
    def channel_id(self) -> int:
        """The id of the relay's channel."""
        return self.channel.id()

    @abstractmethod
    def open(self) -> None:
        """The first client subscribed: subscribe on the bus."""

    @abstractmethod
    def close(self) -> None:
        """The last client left: leave the bus (safe to call when not open)."""

    def replay(self) -> None:  # noqa: B027 (most relays keep nothing to send again)
        """Another client subscribed while the relay is open: send it what is kept."""

    def remove(self) -> None:
        """Leave the bus and unadvertise the channel."""
        self.close()
        self.channel.close()


class Relays(ServerListener):
    """The relays by channel id, and the Foxglove server's listener for subscriptions.

    A relay nobody watches leaves the bus ``linger`` seconds (by ``clock``) after its last
    client left, at the first :meth:`expire` after that. Thread-safe: the server calls
    :meth:`on_subscribe` and :meth:`on_unsubscribe` on its threads while discovery adds and
    removes relays on another. A channel is never closed under the lock, since closing it
    calls :meth:`on_unsubscribe` for its watchers.
    """

    def __init__(self, linger: float = LINGER,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self.linger, self.clock = linger, clock
        self._lock = threading.RLock()
        self._by_topic: dict[str, Relay] = {}
        self._by_channel: dict[int, Relay] = {}
        self._watchers: dict[int, set[int]] = {}
        self._early: dict[int, set[int]] = {}  # subscriptions to channels not added yet
        self._idle: dict[int, float] = {}  # open relays nobody watches -> since when

    def topics(self) -> dict[str, Relay]:
        """The relays now, by topic."""
        with self._lock:
            return dict(self._by_topic)

    def add(self, relay: Relay) -> None:
        """Offer ``relay``'s channel; one already offered on the topic is removed first.

        A client may subscribe as soon as the channel exists, before it is added here: such
        subscriptions were kept aside and open the relay now.
        """
        self.remove(relay.topic)
        with self._lock:
            self._by_topic[relay.topic] = relay
            self._by_channel[relay.channel_id] = relay
            watchers = self._early.pop(relay.channel_id, set())
            self._watchers[relay.channel_id] = watchers
            if watchers:
                _guarded(relay.open, relay.topic, "subscribe")

    def remove(self, topic: str) -> None:
        """Withdraw the relay on ``topic``, if any: unsubscribe on the bus, unadvertise."""
        with self._lock:
            relay = self._by_topic.pop(topic, None)
            if relay is None:
                return
            self._by_channel.pop(relay.channel_id, None)
            self._watchers.pop(relay.channel_id, None)
            self._early.pop(relay.channel_id, None)
            self._idle.pop(relay.channel_id, None)
        _guarded(relay.remove, relay.topic, "remove")

    def remove_all(self) -> None:
        """Withdraw every relay (the server stops)."""
        for topic in list(self.topics()):
            self.remove(topic)

    def subscriptions(self) -> int:
        """Subscriptions held for clients now, over every channel (0 once every client left)."""
        with self._lock:
            return (sum(len(watchers) for watchers in self._watchers.values())
                    + sum(len(early) for early in self._early.values()))

    def lingering(self) -> int:
        """Relays still on the bus that nobody watches (their last client left lately)."""
        with self._lock:
            return len(self._idle)

    def expire(self) -> None:
        """Take off the bus the relays nobody has watched for ``linger`` seconds."""
        with self._lock:
            now = self.clock()
            for channel, since in list(self._idle.items()):
                relay = self._by_channel.get(channel)
                if now - since >= self.linger and relay is not None:
                    del self._idle[channel]
                    _guarded(relay.close, relay.topic, "unsubscribe")

    def watched(self, topic: str) -> int:
        """How many clients watch the channel on ``topic`` now."""
        with self._lock:
            relay = self._by_topic.get(topic)
            return 0 if relay is None else len(self._watchers[relay.channel_id])

    # ------------------------------------------------------------------ the server's listener
    def on_subscribe(self, client: Client, channel: ChannelView) -> None:
        """A client subscribed: the first one opens the relay, others get what it keeps."""
        with self._lock:
            relay = self._by_channel.get(channel.id)
            if relay is None:
                self._early.setdefault(channel.id, set()).add(client.id)
                return
            watchers = self._watchers[channel.id]
            closed = not watchers and self._idle.pop(channel.id, None) is None
            watchers.add(client.id)
            _guarded(relay.open if closed else relay.replay, relay.topic, "subscribe")

    def on_unsubscribe(self, client: Client, channel: ChannelView) -> None:
        """A client unsubscribed (or left): after the last one the relay lingers, then closes."""
        with self._lock:
            early = self._early.get(channel.id)
            if early is not None:
                early.discard(client.id)
                if not early:
                    del self._early[channel.id]
            relay = self._by_channel.get(channel.id)
            watchers = self._watchers.get(channel.id)
            if relay is None or watchers is None or client.id not in watchers:
                return
            watchers.discard(client.id)
            if watchers:
                return
            if self.linger > 0:
                self._idle[channel.id] = self.clock()
            else:
                _guarded(relay.close, relay.topic, "unsubscribe")


def _guarded(action: Any, topic: str, what: str) -> None:
    """Run ``action``; an error is logged, never raised into the server's threads."""
    try:
        action()
    except Exception:
        log.exception("%s: %s failed", topic, what)
