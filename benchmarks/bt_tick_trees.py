"""The trees of the tick benchmark (benchmarks/bt_tick.py), each described once, three ways.

A :class:`Shape` is an engine-neutral tree of Sequences, Priorities and leaves that succeed at
once. It is rendered as a behavior3editor export for cyborg (:func:`to_behavior3_json`, with
services declared on its composites if asked), as py_trees behaviours (:func:`to_py_trees`)
and as plain Python objects for the floor (:func:`to_floor`): the least a recursive walk can do.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Literal

import py_trees

NodeKind = Literal["Sequence", "Priority", "Succeeder"]


# ---------------------------------------------------------------------------- tree shapes
@dataclass(frozen=True)
class Shape:
    """One node of an engine-neutral tree description, with its subtree."""

    kind: NodeKind
    children: tuple[Shape, ...] = ()

    @property
    def node_count(self) -> int:
        return 1 + sum(child.node_count for child in self.children)

    @property
    def depth(self) -> int:
        """Number of levels, counting this node as one."""
        return 1 + max((child.depth for child in self.children), default=0)

    @property
    def visits_per_tick(self) -> int:
        """Nodes visited in one tick when every leaf succeeds: a Sequence visits all its
        children, a Priority stops at its first child (which succeeds)."""
        if self.kind == "Sequence":
            return 1 + sum(child.visits_per_tick for child in self.children)
        if self.kind == "Priority":
            return 1 + (self.children[0].visits_per_tick if self.children else 0)
        return 1


LEAF = Shape("Succeeder")
"""A leaf that succeeds at once; one description serves every place it appears."""


def sequence(*children: Shape) -> Shape:
    return Shape("Sequence", children)


def priority(*children: Shape) -> Shape:
    return Shape("Priority", children)


def wide_shape() -> Shape:
    """Root Sequence -> 10 x Priority(Sequence -> 10 x Sequence -> 10 leaves, fallback leaf)."""
    def block() -> Shape:
        return sequence(*(sequence(*(LEAF for _ in range(10))) for _ in range(10)))

    return sequence(*(priority(block(), LEAF) for _ in range(10)))


def chain_shape(length: int) -> Shape:
    """``length`` composites, alternating Sequence (leaf first) and Priority (leaf last).

    Levels are counted from 1 at the root; odd levels are Sequences. The last composite holds
    two leaves instead of a leaf and a further composite.
    """
    last_kind: NodeKind = "Sequence" if length % 2 else "Priority"
    node = Shape(last_kind, (LEAF, LEAF))
    for level in range(length - 1, 0, -1):
        node = sequence(LEAF, node) if level % 2 else priority(node, LEAF)
    return node


SHAPES: dict[str, Callable[[], Shape]] = {
    "wide": wide_shape,
    "deep50": lambda: chain_shape(50),
    "deep10": lambda: chain_shape(10),
}


# ---------------------------------------------------------------------------- renderers
def to_behavior3_json(shape: Shape, tree_id: str, services: str = "") -> str:
    """The shape as a behavior3editor 0.3.0 single-tree export; ``services`` on composites."""
    nodes: dict[str, dict[str, Any]] = {}

    def add(node: Shape) -> str:
        node_id = f"n{len(nodes)}"
        entry: dict[str, Any] = {"id": node_id, "name": node.kind, "title": node.kind,
                                 "description": "", "properties": {}}
        nodes[node_id] = entry
        if node.kind != "Succeeder":
            entry["children"] = [add(child) for child in node.children]
            if services:
                entry["properties"]["services"] = services
        return node_id

    root = add(shape)
    return json.dumps({"version": "0.3.0", "scope": "tree", "id": tree_id, "title": tree_id,
                       "description": "", "root": root, "properties": {}, "nodes": nodes})


def to_py_trees(shape: Shape) -> Any:
    """The shape as py_trees behaviours, composites without memory."""
    children = [to_py_trees(child) for child in shape.children]
    if shape.kind == "Sequence":
        return py_trees.composites.Sequence("Sequence", memory=False, children=children)
    if shape.kind == "Priority":
        return py_trees.composites.Selector("Priority", memory=False, children=children)
    return py_trees.behaviours.Success("Succeeder")


class FloorLeaf:
    """A leaf of the floor tree: records its visit and succeeds."""

    __slots__ = ()

    def run(self, visited: list[FloorNode]) -> bool:
        visited.append(self)
        return True


class FloorComposite:
    """Runs children in order while they return ``go_on``: True for a Sequence (go on while
    children succeed), False for a Priority (go on while they fail). Records its own visit
    after its children's, in completion order, as cyborg does."""

    __slots__ = ("children", "go_on")

    def __init__(self, children: list[FloorNode], go_on: bool) -> None:
        self.children = children
        self.go_on = go_on

    def run(self, visited: list[FloorNode]) -> bool:
        go_on = self.go_on
        for child in self.children:
            if child.run(visited) is not go_on:
                visited.append(self)
                return not go_on
        visited.append(self)
        return go_on


FloorNode = FloorLeaf | FloorComposite
"""The floor: the least a recursive tree walk in Python can do, one method call per node."""


def to_floor(shape: Shape) -> FloorNode:
    if shape.kind == "Succeeder":
        return FloorLeaf()
    return FloorComposite([to_floor(child) for child in shape.children],
                          go_on=shape.kind == "Sequence")
