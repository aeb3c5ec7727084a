"""The bus as Foxglove channels, kept up to date as topics, robots and tree runners come and go.

A :class:`Bridge` follows the bus graph from its node: every :data:`POLL` seconds, if the graph
changed, it asks :func:`~cyborg.foxglove.catalogue.wanted_channels` what the bus calls for,
advertises a channel for each new offer, unadvertises those whose topic vanished (a publisher
that left) and makes again those whose source changed (a topic's type). The relays subscribe on
the bus only while a client watches (:mod:`cyborg.foxglove.relay`; the bridge takes off the
bus, as it polls, those nobody has watched for a while); the robots' maps and the trees' ticks
are made on a callback thread of their own.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable

import foxglove

from cyborg.bus import Node
from cyborg.bus.executor import CallbackThread
from cyborg.bus.wire import EntityKind
from cyborg.foxglove.catalogue import Offer, wanted_channels
from cyborg.foxglove.derived_relay import DerivedRelay
from cyborg.foxglove.relay import Relay, Relays
from cyborg.foxglove.robot_relays import MapGridRelay, MapSceneRelay, RobotFrameRelay
from cyborg.foxglove.topic_relay import TopicRelay
from cyborg.foxglove.tree_relay import TreeTickRelay

log = logging.getLogger("cyborg.foxglove")

POLL = 0.5
"""Seconds between looks at the bus graph."""
MADE: dict[str, Callable[[Node, str, CallbackThread, foxglove.Context], DerivedRelay]] = {
    "map": MapGridRelay, "map_scene": MapSceneRelay, "frame": RobotFrameRelay,
    "tick": TreeTickRelay}
"""The relay of each kind of made channel (:class:`~cyborg.foxglove.catalogue.Offer`)."""


class Bridge:
    """Keeps ``relays`` (on Foxglove ``context``) in step with the bus that ``node`` sees."""

    def __init__(self, node: Node, context: foxglove.Context, relays: Relays, *,
                 poll: float = POLL) -> None:
        self.node, self.context, self.relays, self.poll = node, context, relays, poll
        self._made_thread = node.callback_thread("made")
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._follow, daemon=True,
                                        name="cyborg-foxglove-bridge")
        self._warned: set[str] = set()
        self._offered: dict[str, tuple[object, ...]] = {}  # topic -> what its relay came from
        self._version = -1

    def start(self) -> None:
        """Advertise what the bus has now, then follow it on a thread of its own."""
        self.update()
        self._thread.start()

    def stop(self) -> None:
        """Stop following and withdraw every channel."""
        self._stop.set()
        if self._thread.is_alive():
            self._thread.join(5)
        self.relays.remove_all()
        self._offered.clear()

    def update(self) -> None:
        """Advertise, withdraw and replace channels so they match the bus now."""
        graph = self.node.context.graph
        self._version = graph.version
        wanted = wanted_channels(graph.entities([EntityKind.PUBLISHER]), self.node.types,
                                 self._warned)
        for topic, key in list(self._offered.items()):
            offer = wanted.get(topic)
            if offer is None or offer.key != key:
                log.info("%s: withdrawn from Foxglove", topic)
                self.relays.remove(topic)
                del self._offered[topic]
        for topic, offer in wanted.items():
            if topic in self._offered:
                continue
            try:
                relay = self._make(topic, offer)
            except Exception:
                log.exception("%s: cannot offer it to Foxglove", topic)
                continue
            self.relays.add(relay)
            self._offered[topic] = offer.key
            log.info("%s: offered to Foxglove", topic)

    def _make(self, topic: str, offer: Offer) -> Relay:
        if offer.kind == "topic":
            return TopicRelay(self.node, topic, offer.type_name, latched=offer.latched,
                              context=self.context)
        return MADE[offer.kind](self.node, offer.namespace, self._made_thread, self.context)

    def _follow(self) -> None:
        while not self._stop.wait(self.poll):
            self.relays.expire()
            if self.node.context.graph.version == self._version:
                continue
            try:
                self.update()
            except Exception:  # a defect: say it, keep following
                log.exception("following the bus failed")
