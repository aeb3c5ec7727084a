"""What a tree file says, in plain data: projects, trees, nodes and node definitions.

The readers of both editor formats (:mod:`cyborg.bt.editor_format` for behavior3editor 0.3.0,
:mod:`cyborg.bt.editor_v1` for 1.x) produce these; :mod:`cyborg.bt.builder` turns them into
live nodes.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Any

from cyborg.bt.problems import Problem

_PLACEHOLDER = re.compile(r"<(\w+)>")


def render_title(title: str, properties: dict[str, Any]) -> str:
    """Fill ``<prop>`` placeholders from ``properties``, as the editor displays titles.

    ``render_title("MoveTo <location>", {"location": "home"}) == "MoveTo home"``; placeholders
    without a matching property stay as they are.
    """

    def fill(match: re.Match[str]) -> str:
        key = match.group(1)
        return str(properties[key]) if key in properties else match.group(0)

    return _PLACEHOLDER.sub(fill, title)


@dataclass
class NodeSpec:
    """One node block as exported."""

    id: str
    name: str
    title: str
    description: str
    properties: dict[str, Any]
    children: list[str]
    line: int | None = None
    shape: str = "leaf"
    """How the block was exported: ``composite`` (``children``), ``decorator`` (``child``) or
    ``leaf`` (neither). Used only for nodes with no Python class."""
    inputs: list[str] = field(default_factory=list)
    """behavior3 v1: the blackboard key bound to each input port, in port order ("" unbound)."""
    outputs: list[str] = field(default_factory=list)
    """behavior3 v1: the blackboard key bound to each output port, in port order."""
    foreign: str = ""
    """behavior3 v1: what the file's stock node of this name does, when cyborg has no node
    that means the same (see :mod:`cyborg.bt.editor_v1_names`)."""

    @property
    def label(self) -> str:
        return render_title(self.title, self.properties)


@dataclass
class TreeSpec:
    """One tree: a flat map of nodes and the id of the node under the Root block."""

    id: str
    title: str
    description: str
    root: str | None
    properties: dict[str, Any]
    nodes: dict[str, NodeSpec]
    line: int | None = None
    source: str = ""
    """The file the tree was read from, when not the project's own (a v1 subtree file)."""

    @property
    def display_name(self) -> str:
        return self.title or self.id


@dataclass
class NodeDefinition:
    """A custom node declared in the file (the editor's palette entry)."""

    name: str
    category: str
    title: str
    properties: dict[str, Any]
    line: int | None = None
    inputs: list[str] = field(default_factory=list)
    """behavior3 v1: the input ports declared (``"target?"`` optional, ``"args..."`` repeats)."""
    outputs: list[str] = field(default_factory=list)
    source: str = ""
    """The file that declared it, when not the tree file itself (a ``.b3-setting``)."""


@dataclass
class ProjectSpec:
    """Everything read from one export file."""

    source: str
    kind: str
    """``project``, ``tree``, ``nodes`` or ``desktop`` (behavior3editor 0.3.0), or ``v1``
    (a behavior3editor 1.x tree file, with the files it references)."""
    trees: list[TreeSpec] = field(default_factory=list)
    selected_tree: str | None = None
    definitions: list[NodeDefinition] = field(default_factory=list)
    problems: list[Problem] = field(default_factory=list)
    """Warnings found while reading (errors raise :class:`TreeLoadError` instead)."""

    def tree_by_id(self) -> dict[str, TreeSpec]:
        return {tree.id: tree for tree in self.trees}
