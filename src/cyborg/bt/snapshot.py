"""What a tree looks like, and what happened in one tick.

:class:`TreeStructure` is the tree's shape, built once per tree: every node with its stable id,
label, name, category, subtree depth and children. Its JSON form (schema
``cyborg.bt.structure/1``, in ``structure.schema.json`` beside this module and described in
docs/tree-structure.md) is what monitors draw.

:class:`TickSnapshot` is produced after every tick. It keeps references to the tick's own lists
(no copying in the hot path); ids and JSON are computed only when asked for.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from cyborg.bt.status import Status

if TYPE_CHECKING:
    from cyborg.bt.node import Node
    from cyborg.bt.service_runner import ScheduledService, ServiceState
    from cyborg.bt.tree import Tree

SCHEMA = "cyborg.bt.structure/1"


class TickSnapshot:
    """The result of one tick: root status, nodes visited with their status, active path."""

    __slots__ = ("_active", "_durations", "_halted", "_halted_ids", "_running", "_statuses",
                 "_visited", "_visits", "duration", "services", "status", "tick", "time")

    def __init__(self, tick: int, time: float, duration: float, status: Status,
                 visits: list[tuple[Node, Status]], running: list[Node],
                 halted: list[Node], durations: dict[int, float] | None = None,
                 services: tuple[ServiceState, ...] | None = None) -> None:
        self.tick = tick
        """Tick number, from 1."""
        self.time = time
        """Clock time at which the tick began, in seconds."""
        self.duration = duration
        """Wall time the tick took, in seconds."""
        self.status = status
        """The root's status."""
        self.services = services
        """After the tick, each service attached to a composite: whether it runs, when it
        last ran, what it wrote (:class:`~cyborg.bt.service_runner.ServiceState`); ``None``
        when the tree has no services."""
        self._visits = visits
        self._running = running
        self._halted = halted
        self._durations = durations or {}
        self._visited: list[tuple[str, Status]] | None = None
        self._statuses: dict[str, Status] | None = None
        self._active: list[str] | None = None
        self._halted_ids: list[str] | None = None

    @property
    def visit_count(self) -> int:
        """How many visits this tick made, without building :attr:`visited`."""
        return len(self._visits)

    # The id lists are built on first use only: most ticks' snapshots are never read in full.
    @property
    def visited(self) -> list[tuple[str, Status]]:
        """``(node id, status)`` for each node ticked, in completion order (children first)."""
        if self._visited is None:
            self._visited = [(node.uid, status) for node, status in self._visits]
        return self._visited

    @property
    def timed(self) -> bool:
        """Whether this tick's visits were timed.

        They are while :attr:`Tree.timing <cyborg.bt.tree.Tree.timing>` is on.
        """
        return bool(self._durations)

    @property
    def visit_durations(self) -> list[float]:
        """Wall time of each visit in :attr:`visited`, in seconds; NaN where it was not timed.

        A visit's time covers the node and its subtree, breakpoint waits excluded.
        """
        durations = self._durations
        nan = float("nan")
        return [durations.get(index, nan) for index in range(len(self._visits))]

    @property
    def statuses(self) -> dict[str, Status]:
        """Status of each node ticked in this tick, by node id."""
        if self._statuses is None:
            self._statuses = {node.uid: status for node, status in self._visits}
        return self._statuses

    @property
    def active(self) -> list[str]:
        """Ids of the nodes RUNNING after this tick, root first: the active path.

        With a Parallel it is a subtree, listed depth first.
        """
        if self._active is None:
            self._active = [node.uid for node in sorted(self._running, key=_index)]
        return self._active

    @property
    def halted(self) -> list[str]:
        """Ids of the nodes halted in this tick, in the order they were halted."""
        if self._halted_ids is None:
            self._halted_ids = [node.uid for node in self._halted]
        return self._halted_ids

    def to_json(self) -> dict[str, Any]:
        """The tick as a JSON-ready dict, with statuses as lower-case names.

        Its keys: ``{"tick", "time", "duration", "status", "visited", "active", "halted"}``,
        and ``"services"`` (each :meth:`ServiceState.to_json
        <cyborg.bt.service_runner.ServiceState.to_json>`) when the tree has services.
        """
        data: dict[str, Any] = {
            "tick": self.tick,
            "time": self.time,
            "duration": self.duration,
            "status": self.status.label,
            "visited": [[uid, status.label] for uid, status in self.visited],
            "active": self.active,
            "halted": self.halted,
        }
        if self.services is not None:
            data["services"] = [state.to_json() for state in self.services]
        return data

    def __repr__(self) -> str:
        return (f"<TickSnapshot tick={self.tick} status={self.status.name} "
                f"visited={self.visit_count} active={len(self._running)}>")


def _index(node: Node) -> int:
    return node.index


@dataclass(frozen=True)
class TreeStructure:
    """The shape of a tree, as JSON-ready nested dicts (see :meth:`to_json`)."""

    root: dict[str, Any]
    tree_id: str
    title: str
    source: str
    node_count: int

    @classmethod
    def of(cls, tree: Tree) -> TreeStructure:
        """The structure of ``tree``, its nodes walked without recursion."""
        attached: dict[Node, list[ScheduledService]] = {}
        for scheduled in tree.services.services if tree.services is not None else ():
            attached.setdefault(scheduled.composite, []).append(scheduled)
        return cls(_describe(tree.root, attached), tree.tree_id, tree.title, tree.source,
                   len(tree.nodes))

    def to_json(self) -> dict[str, Any]:
        """The JSON form, schema ``cyborg.bt.structure/1``, as JSON-ready nested dicts.

        ``{"schema", "tree_id", "title", "source", "node_count", "root"}``; each node is
        ``{"id", "node_id", "name", "title", "label", "category", "depth", "index",
        "properties", "children"}``; tree nodes add ``"tree_id"`` and composites carrying
        services add ``"services"``: ``[{"name", "declaration", "interval", "deviation",
        "restart_on_activation", "run_on_activation"}]``, in declaration order.
        """
        return {
            "schema": SCHEMA,
            "tree_id": self.tree_id,
            "title": self.title,
            "source": self.source,
            "node_count": self.node_count,
            "root": self.root,
        }


def _describe(root: Node, attached: dict[Node, list[ScheduledService]]) -> dict[str, Any]:
    """The nested entries of ``root`` and its descendants, built without recursion."""
    top = _entry(root, attached)
    pending = [(root, top)]
    while pending:
        node, entry = pending.pop()
        children = entry["children"]
        for child in node.children:
            child_entry = _entry(child, attached)
            children.append(child_entry)
            pending.append((child, child_entry))
    return top


def _entry(node: Node, attached: dict[Node, list[ScheduledService]]) -> dict[str, Any]:
    """One node's entry, its ``children`` still empty."""
    entry: dict[str, Any] = {
        "id": node.uid,
        "node_id": node.node_id,
        "name": node.name,
        "title": node.title,
        "label": node.label,
        "category": node.category.value,
        "depth": node.subtree_depth,
        "index": node.index,
        "properties": dict(node.properties),
    }
    tree_id = getattr(node, "tree_id", None)
    if tree_id is not None:
        entry["tree_id"] = tree_id
    services = attached.get(node)
    if services:
        entry["services"] = [{"name": scheduled.service.name,
                              "declaration": scheduled.declaration,
                              **scheduled.timing.to_json()} for scheduled in services]
    entry["children"] = []
    return entry
