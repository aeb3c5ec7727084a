"""The blackboard: data shared between nodes, in behavior3's three scopes.

* **global** — application data every node can read (named goals, battery state);
* **tree** — one dict per tree *instance* (the root tree, and each subtree reference), keyed by
  the instance's id, so a subtree used twice keeps two separate tree memories;
* **node** — one dict per node, keyed by the node's stable id; stock nodes keep their state here
  (MemSequence's ``running_child``, Wait's ``start``, Limiter's ``completed``).

Beside the scopes, :attr:`Blackboard.resources` holds handles to the outside world that nodes
need but that are not data (a connection to the robot, a camera). They are given by whoever
runs the tree, never shown in :meth:`Blackboard.as_dict`, and survive a reload.

Nodes reach the scopes as ``self.blackboard``, ``self.tree_memory`` and ``self.memory``.
:meth:`Blackboard.as_dict` returns all three for inspection.
"""

from __future__ import annotations

from collections.abc import Iterator, MutableMapping
from typing import Any


class Blackboard(MutableMapping[str, Any]):
    """Global scope as a mapping, with tree and node scopes beside it."""

    def __init__(self, initial: dict[str, Any] | None = None, *,
                 resources: dict[str, Any] | None = None) -> None:
        self.globals: dict[str, Any] = dict(initial or {})
        self.trees: dict[str, dict[str, Any]] = {}
        self.nodes: dict[str, dict[str, Any]] = {}
        self.resources: dict[str, Any] = dict(resources or {})
        """Handles for nodes to act through (``"robot"``: the robot's interface); not data."""

    # Global scope: the mapping interface.
    def __getitem__(self, key: str) -> Any:
        return self.globals[key]

    def __setitem__(self, key: str, value: Any) -> None:
        self.globals[key] = value

    def __delitem__(self, key: str) -> None:
        del self.globals[key]

    def __iter__(self) -> Iterator[str]:
        return iter(self.globals)

    def __len__(self) -> int:
        return len(self.globals)

    # behavior3-style access to any scope.
    def get(self, key: str, default: Any = None, *, tree: str | None = None,
            node: str | None = None) -> Any:
        """Reads ``key`` from one scope; ``default`` when the key is missing there.

        The scope is the node's (``node``: its uid) if given, else the tree instance's
        (``tree``: its uid) if given, else the global scope.
        """
        return self._scope(tree, node).get(key, default)

    def set(self, key: str, value: Any, *, tree: str | None = None,
            node: str | None = None) -> None:
        """Writes ``key`` into the scope chosen as for :meth:`get`."""
        self._scope(tree, node)[key] = value

    def tree_scope(self, tree_uid: str) -> dict[str, Any]:
        """The memory of one tree instance, created on first use."""
        scope = self.trees.get(tree_uid)
        if scope is None:
            scope = self.trees[tree_uid] = {}
        return scope

    def node_scope(self, node_uid: str) -> dict[str, Any]:
        """The memory of one node, created on first use."""
        scope = self.nodes.get(node_uid)
        if scope is None:
            scope = self.nodes[node_uid] = {}
        return scope

    def as_dict(self) -> dict[str, Any]:
        """A copy of all three scopes, for inspection; empty node scopes are left out.

        Safe to call from another thread while the tree ticks: each dict is copied in one step.
        """
        return {
            "global": dict(self.globals),
            "trees": {uid: dict(scope) for uid, scope in dict(self.trees).items() if scope},
            "nodes": {uid: dict(scope) for uid, scope in dict(self.nodes).items() if scope},
        }

    def _scope(self, tree: str | None, node: str | None) -> dict[str, Any]:
        if node is not None:
            return self.node_scope(node)
        if tree is not None:
            return self.tree_scope(tree)
        return self.globals
