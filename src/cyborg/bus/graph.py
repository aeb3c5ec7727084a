"""The ROS graph as seen through rmw_zenoh liveliness tokens: nodes, topics, services.

Every node and endpoint (ours or a ROS 2 peer's) holds a liveliness token; :class:`Graph` keeps
the set of tokens alive now, fed by a liveliness subscriber with history. When a process dies
its tokens vanish as soon as its Zenoh session is gone, so it drops out of ``node list``.
"""

from __future__ import annotations

import re
import threading
from collections.abc import Callable, Iterable
from dataclasses import dataclass

from cyborg.bus.wire import LIVELINESS_PREFIX, EntityKind, unmangle

NODE_CHUNKS = 9
ENDPOINT_CHUNKS = 13
_DDS_TYPE = re.compile(r"^[^:/]+::[^:/]+::dds_::[^:/]+$")


@dataclass(frozen=True)
class GraphEntity:
    """One liveliness token, parsed. ``topic``, ``dds_type`` etc. are empty for a node."""

    key: str
    domain: int
    zid: str
    node_id: int
    entity_id: int
    kind: EntityKind
    enclave: str
    namespace: str
    node: str
    topic: str = ""
    dds_type: str = ""
    type_hash: str = ""
    qos: str = ""

    @property
    def node_name(self) -> str:
        """The node's fully qualified name, ``/ns/node``."""
        return f"{self.namespace.rstrip('/')}/{self.node}"

    @property
    def type_name(self) -> str:
        """``std_msgs::msg::dds_::String_`` -> ``std_msgs/msg/String``."""
        if not self.dds_type:
            return ""
        package, kind, _dds, name = self.dds_type.split("::")
        return f"{package}/{kind}/{name.removesuffix('_')}"

    @property
    def latched(self) -> bool:
        """Whether the endpoint's QoS is transient-local (durability field ``1``)."""
        fields = self.qos.split(":")
        return len(fields) > 1 and fields[1] == "1"


def parse_token(key: str) -> GraphEntity | None:
    """A liveliness key as a graph entity; ``None`` for keys that are not rmw_zenoh tokens."""
    chunks = key.split("/")
    if len(chunks) not in (NODE_CHUNKS, ENDPOINT_CHUNKS) or chunks[0] != LIVELINESS_PREFIX:
        return None
    try:
        kind = EntityKind(chunks[5])
        base = dict(key=key, domain=int(chunks[1]), zid=chunks[2], node_id=int(chunks[3]),
                    entity_id=int(chunks[4]), kind=kind, enclave=unmangle(chunks[6]),
                    namespace=unmangle(chunks[7]) or "/", node=chunks[8])
    except ValueError:
        return None
    if not chunks[8]:
        return None
    if kind is EntityKind.NODE:
        return GraphEntity(**base) if len(chunks) == NODE_CHUNKS else None  # type: ignore[arg-type]
    if len(chunks) != ENDPOINT_CHUNKS or not _DDS_TYPE.match(chunks[10]):
        return None  # e.g. a forged token whose type would break every query naming types
    topic = unmangle(chunks[9])
    return GraphEntity(**base, topic=topic if topic.startswith("/") else "/" + topic,  # type: ignore[arg-type]
                       dds_type=chunks[10], type_hash=chunks[11], qos=chunks[12])


class Graph:
    """The live tokens of one domain, with queries in the style of ``ros2 node/topic list``.

    Thread-safe: tokens arrive on Zenoh threads, queries come from anywhere. Tokens of other
    domains than ``domain`` are ignored.
    """

    def __init__(self, domain: int) -> None:
        self.domain = domain
        self._entities: dict[str, GraphEntity] = {}
        # endpoints by (topic, kind): a publisher asks for its subscriptions on every message
        self._by_endpoint: dict[tuple[str, EntityKind], dict[str, GraphEntity]] = {}
        self.version = 0
        """Counts changes, so a caller can keep an answer until the graph changes."""
        self._lock = threading.RLock()  # predicates of wait_for query the graph
        self._changed = threading.Condition(self._lock)
        self._listeners: list[Callable[[], None]] = []
        self._departures: list[Callable[[GraphEntity], None]] = []

    # ------------------------------------------------------------------ updates
    def add(self, key: str) -> None:
        """Record a token that appeared; keys that are not tokens of this domain are ignored."""
        entity = parse_token(key)
        if entity is None or entity.domain != self.domain:
            return
        with self._changed:
            self._drop(key)
            self._entities[key] = entity
            self._by_endpoint.setdefault((entity.topic, entity.kind), {})[key] = entity
            self.version += 1
            self._changed.notify_all()
        self._notify()

    def remove(self, key: str) -> None:
        """Forget a token that vanished, then tell the departure and change listeners."""
        with self._changed:
            entity = self._drop(key)
            if entity is None:
                return
            self._changed.notify_all()
        for departure in list(self._departures):
            departure(entity)
        self._notify()

    def _drop(self, key: str) -> GraphEntity | None:
        entity = self._entities.pop(key, None)
        if entity is None:
            return None
        index = (entity.topic, entity.kind)
        same = self._by_endpoint[index]
        del same[key]
        if not same:
            del self._by_endpoint[index]
        self.version += 1
        return entity

    def on_change(self, listener: Callable[[], None]) -> Callable[[], None]:
        """Call ``listener()`` (on a Zenoh thread) whenever a token appears or vanishes.

        Returns a function that removes the listener.
        """
        self._listeners.append(listener)
        return lambda: self._listeners.remove(listener) if listener in self._listeners else None

    def on_departure(self, listener: Callable[[GraphEntity], None]) -> None:
        """Call ``listener(entity)`` (on a Zenoh thread) for each entity that leaves the graph.

        For example, to forget what was kept about a publisher.
        """
        self._departures.append(listener)

    def _notify(self) -> None:
        for listener in list(self._listeners):
            listener()

    def wait_for(self, predicate: Callable[[Graph], bool], timeout: float) -> bool:
        """Block until ``predicate(graph)`` holds or ``timeout`` seconds pass."""
        with self._changed:
            return self._changed.wait_for(lambda: predicate(self), timeout)

    # ------------------------------------------------------------------ queries
    def entities(self, kinds: Iterable[EntityKind] | None = None) -> list[GraphEntity]:
        """The live entities of ``kinds`` (default: all), in no particular order."""
        wanted = set(kinds) if kinds is not None else None
        with self._lock:
            return [e for e in self._entities.values() if wanted is None or e.kind in wanted]

    def nodes(self) -> list[str]:
        """Fully qualified names of the live nodes, sorted (a name shared by two is listed once)."""
        return sorted({e.node_name for e in self.entities([EntityKind.NODE])})

    def topics(self) -> dict[str, set[str]]:
        """Topic -> its type names, from publishers and subscriptions."""
        result: dict[str, set[str]] = {}
        for e in self.entities([EntityKind.PUBLISHER, EntityKind.SUBSCRIPTION]):
            result.setdefault(e.topic, set()).add(e.type_name)
        return result

    def services(self) -> dict[str, set[str]]:
        """Service -> its type names, from servers."""
        result: dict[str, set[str]] = {}
        for e in self.entities([EntityKind.SERVICE_SERVER]):
            result.setdefault(e.topic, set()).add(e.type_name)
        return result

    def endpoints(self, topic: str, kind: EntityKind) -> list[GraphEntity]:
        """The live endpoints of ``kind`` on ``topic`` (or service name); a cheap index lookup."""
        with self._lock:
            return list(self._by_endpoint.get((topic, kind), {}).values())

    def count(self, topic: str, kind: EntityKind, *, exclude_zid: str = "") -> int:
        """How many endpoints of ``kind`` exist on ``topic`` (optionally not in one session)."""
        return sum(1 for e in self.endpoints(topic, kind) if e.zid != exclude_zid)

    def node_endpoints(self, node_name: str) -> list[GraphEntity]:
        """The endpoints (not the node tokens) of nodes named ``node_name``, ``/ns/node``."""
        return [e for e in self.entities() if e.node_name == node_name
                and e.kind is not EntityKind.NODE]
