"""Which channels the bus calls for now: its topics, and for each robot and tree runner, more.

:func:`wanted_channels` reads the bus graph's publishers and returns, by channel topic, what
each channel is made from (an :class:`Offer`):

* every topic with a publisher, passed through (:class:`~cyborg.foxglove.topic_relay.
  TopicRelay`), latched when a publisher of it is; except hidden topics (a name part starting
  with ``_``, as ``_action/status``: ``ros2 topic list`` hides them too) and topics whose type
  this bus does not know (no definition to give Foxglove; logged once);
* for each robot (found by its pose) whose map is published, its map as a grid and as a scene,
  and its frame where its odometry is published (:mod:`cyborg.foxglove.robot_relays`);
* for each tree runner (found by its structure topic) whose status is published, its ticks as
  JSON (:mod:`cyborg.foxglove.tree_relay`).

A bus topic whose name is one of these made channels' names is not passed through: the made
channel takes the name.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from typing import Any

from cyborg.bus import MessageTypes
from cyborg.bus.graph import GraphEntity
from cyborg.bus.wire import EntityKind
from cyborg.foxglove import robot_relays, tree_relay
from cyborg.interfaces import robot, tree_runner
from cyborg.interfaces.contract import resolve

log = logging.getLogger("cyborg.foxglove")


@dataclass(frozen=True)
class Offer:
    """One channel to offer: what it is made from (``key``), and its ``kind`` of relay."""

    kind: str
    """``topic`` (a bus topic passed through), ``map``, ``map_scene``, ``frame`` or ``tick``."""
    key: tuple[Any, ...]
    """What the relay is made from: a relay whose key changed is made again."""
    namespace: str = ""
    """The robot's or tree runner's namespace, for a made channel."""
    type_name: str = ""
    """The topic's type, for a bus topic."""
    latched: bool = False
    """Whether a publisher of the bus topic is latched."""


def _hidden(topic: str) -> bool:
    return any(part.startswith("_") for part in topic.split("/"))


def wanted_channels(publishers: list[GraphEntity], types: MessageTypes,
                    warned: set[str] | None = None) -> dict[str, Offer]:
    """The channels the bus's ``publishers`` call for, by topic (see the module's description).

    ``warned`` collects the topics already logged as not offered, so each is logged once.
    """
    warned = set() if warned is None else warned
    topics: dict[str, tuple[str, bool]] = {}
    for entity in publishers:
        if entity.kind is not EntityKind.PUBLISHER or _hidden(entity.topic):
            continue
        type_name, latched = topics.get(entity.topic, (entity.type_name, False))
        if type_name != entity.type_name:
            if entity.topic not in warned:
                warned.add(entity.topic)
                log.warning("%s: published as %s and %s; offering %s only", entity.topic,
                            type_name, entity.type_name, type_name)
            continue
        topics[entity.topic] = (type_name, latched or entity.latched)
    made: dict[str, Offer] = {}
    for topic, (type_name, _latched) in topics.items():
        made.update(_made_for(topic, type_name, topics))
    offers: dict[str, Offer] = {}
    for topic, (type_name, latched) in sorted(topics.items()):
        if topic in made:
            continue
        if type_name not in types:
            if topic not in warned:
                warned.add(topic)
                log.warning("%s: type %s is not known here; not offered to Foxglove", topic,
                            type_name)
            continue
        offers[topic] = Offer("topic", ("topic", type_name, latched), type_name=type_name,
                              latched=latched)
    return {**offers, **made}


def _made_for(topic: str, type_name: str,
              topics: dict[str, tuple[str, bool]]) -> dict[str, Offer]:
    """The made channels that ``topic`` (a robot's pose, a runner's structure) calls for."""
    def published(namespace: str, name: str, wanted: str) -> bool:
        return topics.get(resolve(namespace, name), ("", False))[0] == wanted

    made: dict[str, Offer] = {}
    namespace = robot.robot_namespace(topic, type_name)
    if namespace is not None:
        if published(namespace, robot.MAP_GEOMETRY.name, robot.MAP_GEOMETRY.type_name):
            for kind, channel in (("map", robot_relays.MAP_CHANNEL),
                                  ("map_scene", robot_relays.SCENE_CHANNEL)):
                made[resolve(namespace, channel)] = Offer(kind, (kind, namespace), namespace)
        if published(namespace, robot.ODOM.name, robot.ODOM.type_name):
            made[resolve(namespace, robot_relays.FRAME_CHANNEL)] = Offer(
                "frame", ("frame", namespace), namespace)
    runner = tree_runner.runner_namespace(topic, type_name)
    if runner is not None and published(runner, tree_runner.STATUS.name,
                                        tree_runner.STATUS.type_name):
        made[resolve(runner, tree_relay.TICK_CHANNEL)] = Offer("tick", ("tick", runner), runner)
    return made
