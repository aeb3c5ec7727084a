"""Building behavior3editor JSON from compact Python specs, for tests.

    spec = N("Sequence", N("Scripted", script="SR"), N("Wait", milliseconds=100))
    tree = tree_from(spec)

`Scripted` is an action whose results follow a script of letters (S=SUCCESS, F=FAILURE,
R=RUNNING, E=ERROR, X=raise), one letter per tick of the node, repeating the last letter; it
logs its lifecycle hooks into `EVENTS`, a list shared through the tree's blackboard.
"""

from __future__ import annotations

import itertools
import json
from dataclasses import dataclass, field
from typing import Any

from cyborg.bt import (
    Action,
    Blackboard,
    Decorator,
    ManualClock,
    NodeRegistry,
    ServiceRegistry,
    Status,
    Tree,
    default_registry,
    loads_tree,
)

LETTERS = {"S": Status.SUCCESS, "F": Status.FAILURE, "R": Status.RUNNING, "E": Status.ERROR}


class Scripted(Action):
    """An action that plays a script of statuses and records its lifecycle."""

    def __init__(self, script: str = "S", tag: str = "") -> None:
        self.script = script
        self.tag = tag

    def _log(self, event: str) -> None:
        self.blackboard.setdefault("events", []).append((event, self.tag or self.uid))

    def on_start(self) -> None:
        self._log("start")

    def tick(self) -> Status:
        step = self.memory.get("step", 0)
        self.memory["step"] = step + 1
        letter = self.script[min(step, len(self.script) - 1)]
        self._log("tick")
        if letter == "X":
            raise RuntimeError(f"scripted failure in {self.tag or self.uid}")
        return LETTERS[letter]

    def on_end(self, status: Status) -> None:
        self._log(f"end:{status.label}")

    def on_halt(self) -> None:
        self._log("halt")


def registry() -> NodeRegistry:
    reg = default_registry(entry_points=False)
    reg.add(Scripted)
    return reg


_ids = itertools.count(1)


@dataclass
class N:
    """A node spec: name, children, properties; `id` defaults to a fresh one."""

    name: str
    children: tuple[N, ...] = ()
    props: dict[str, Any] = field(default_factory=dict)
    id: str = ""
    title: str = ""

    def __init__(self, name: str, *children: N, id: str = "", title: str = "",
                 **props: Any) -> None:
        self.name = name
        self.children = children
        self.props = props
        self.id = id or f"n{next(_ids)}"
        self.title = title or name


def _nodes(spec: N, reg: NodeRegistry, out: dict[str, Any]) -> None:
    entry: dict[str, Any] = {"id": spec.id, "name": spec.name, "title": spec.title,
                             "description": "", "properties": spec.props,
                             "display": {"x": 0, "y": 0}}
    node_type = reg.get(spec.name)
    if node_type is not None and issubclass(node_type.cls, Decorator):
        if spec.children:
            entry["child"] = spec.children[0].id
    elif spec.children or (node_type is not None and node_type.category.value == "composite"):
        entry["children"] = [child.id for child in spec.children]
    out[spec.id] = entry
    for child in spec.children:
        _nodes(child, reg, out)


def tree_json(spec: N, *, tree_id: str = "main", title: str = "Main",
              reg: NodeRegistry | None = None) -> dict[str, Any]:
    nodes: dict[str, Any] = {}
    _nodes(spec, reg or registry(), nodes)
    return {"version": "0.3.0", "scope": "tree", "id": tree_id, "title": title,
            "description": "", "root": spec.id, "properties": {}, "nodes": nodes,
            "display": {"camera_x": 0, "camera_y": 0, "camera_z": 1, "x": 0, "y": 0}}


def project_json(trees: list[dict[str, Any]], selected: str | None = None) -> str:
    return json.dumps({"version": "0.3.0", "scope": "project",
                       "selectedTree": selected if selected is not None else trees[0]["id"],
                       "trees": trees, "custom_nodes": []}, indent=2)


def tree_from(spec: N, *, clock: ManualClock | None = None,
              reg: NodeRegistry | None = None, services: ServiceRegistry | None = None,
              resources: dict[str, Any] | None = None) -> Tree:
    """A live tree for `spec`, on a ManualClock at 0 unless given, with an `events` list."""
    reg = reg or registry()
    text = json.dumps(tree_json(spec, reg=reg), indent=2)
    return loads_tree(text, registry=reg, clock=clock or ManualClock(), services=services,
                      blackboard=Blackboard({"events": []}, resources=resources))


def events(tree: Tree) -> list[tuple[str, str]]:
    """The lifecycle log of the Scripted nodes, then cleared."""
    log: list[tuple[str, str]] = tree.blackboard["events"]
    copy = list(log)
    log.clear()
    return copy
