"""What a tree file says, in plain data: projects, trees, nodes and node definitions.

The readers of both editor formats (:mod:`cyborg.bt.editor_format` for behavior3editor 0.3.0,
:mod:`cyborg.bt.editor_v1` for 1.x) produce these; :mod:`cyborg.bt.builder` turns them into
live nodes.
:func:`choose_tree` picks the tree of a project to run.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Any

from cyborg.bt.problems import Problem, shown

_PLACEHOLDER = re.compile(r"<(\w+)>")


def render_title(title: str, properties: dict[str, Any]) -> str:
    """``title`` with ``<prop>`` placeholders filled from ``properties``, as the editor shows it.

    ``render_title("MoveTo <location>", {"location": "home"}) == "MoveTo home"``; placeholders
    without a matching property stay as they are.
    """

    def fill(match: re.Match[str]) -> str:
        key = match.group(1)
        if key not in properties:
            return match.group(0)
        value = properties[key]
        if isinstance(value, str | int | float) or value is None:
            return str(value)
        return shown(value)  # a list or object, maybe huge: cut short

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
    arg_names: dict[str, str] = field(default_factory=dict)
    """behavior3 v1: the file's name of each property the reader renamed (``milliseconds``:
    ``time``), so that messages name what the file says."""

    @property
    def label(self) -> str:
        """The title with its ``<property>`` placeholders filled in (:func:`render_title`)."""
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
        """The name messages give the tree: its title, or its id if it has none."""
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
        """A new dict of the project's trees by id."""
        return {tree.id: tree for tree in self.trees}


def choose_tree(project: ProjectSpec, wanted: str | None) -> tuple[TreeSpec | None, str]:
    """The tree to run: by id or title if ``wanted``, else the selected one.

    Returns the tree, or None and the reason.
    """
    trees = project.trees
    listing = ", ".join(f"{t.title!r} ({t.id})" for t in trees) or "none"
    if not trees:
        return None, "the file holds no tree (only node definitions?)"
    if wanted is not None:
        by_id = [t for t in trees if t.id == wanted]
        by_title = [t for t in trees if t.title == wanted]
        if by_id:
            return by_id[0], ""
        if len(by_title) == 1:
            return by_title[0], ""
        if by_title:
            return None, f"several trees are titled {wanted!r}; pick one by id: {listing}"
        return None, f"no tree has the id or title {wanted!r}; trees: {listing}"
    if project.selected_tree is not None:
        for tree in trees:
            if tree.id == project.selected_tree:
                return tree, ""
        return None, f"selectedTree {project.selected_tree!r} is not in the file; trees: {listing}"
    referenced = {node.name for tree in trees for node in tree.nodes.values()}
    tops = [tree for tree in trees if tree.id not in referenced]
    if len(trees) == 1 or len(tops) == 1:
        return (trees[0] if len(trees) == 1 else tops[0]), ""
    return None, f"no selectedTree in the file; pick a tree by id or title: {listing}"
