"""Reading behavior3editor 0.3.0 exports into plain specs.

Four shapes are accepted (see the editor's export manager):

* a **project** — ``{"scope": "project", "trees": [...], "selectedTree": id,
  "custom_nodes": [...]}``;
* a **single tree** — ``{"scope": "tree", "id", "title", "root", "nodes": {...}}``, possibly
  with its own ``custom_nodes``;
* a **node list** — a bare array of custom node definitions ("Nodes as JSON");
* the desktop editor's **project file** — ``{"name", "description", "data": <project>, "path"}``.

Unknown keys (``display``, ``version``, ``scope``, a hand-added ``category``) are ignored.
Children keep the order of the file, which is what the editor exported. Every node, tree and
definition remembers the line it starts on, so problems can point into the file.
"""

from __future__ import annotations

import bisect
import json
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from cyborg.bt.problems import Problem, Severity, TreeLoadError

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


@dataclass
class ProjectSpec:
    """Everything read from one export file."""

    source: str
    kind: str
    """``project``, ``tree``, ``nodes`` or ``desktop``."""
    trees: list[TreeSpec] = field(default_factory=list)
    selected_tree: str | None = None
    definitions: list[NodeDefinition] = field(default_factory=list)
    problems: list[Problem] = field(default_factory=list)
    """Warnings found while reading (errors raise :class:`TreeLoadError` instead)."""

    def tree_by_id(self) -> dict[str, TreeSpec]:
        return {tree.id: tree for tree in self.trees}


class _Lines:
    """Line numbers of object keys and ``"id"`` values in the raw JSON text."""

    def __init__(self, text: str) -> None:
        self._starts = [0] + [m.end() for m in re.finditer("\n", text)]
        self._keys: dict[str, int] = {}
        for match in re.finditer(r'"((?:[^"\\]|\\.)*)"\s*:\s*\{', text):
            self._keys.setdefault(match.group(1), self._line(match.start()))
        self._ids: dict[str, int] = {}
        for match in re.finditer(r'"(?:id|name)"\s*:\s*"((?:[^"\\]|\\.)*)"', text):
            self._ids.setdefault(match.group(1), self._line(match.start()))

    def _line(self, offset: int) -> int:
        return bisect.bisect_right(self._starts, offset)

    def of_key(self, key: str) -> int | None:
        return self._keys.get(key, self._ids.get(key))

    def of_id(self, value: str) -> int | None:
        return self._ids.get(value, self._keys.get(value))


class _Reader:
    def __init__(self, text: str, source: str) -> None:
        self.source = source
        self.lines = _Lines(text)
        self.problems: list[Problem] = []

    def problem(self, message: str, *, line: int | None = None, tree: TreeSpec | None = None,
                node: str | None = None, title: str | None = None, key: str | None = None,
                severity: Severity = Severity.ERROR) -> None:
        self.problems.append(Problem(
            message, self.source, line, None, tree.display_name if tree else None, node, title,
            key, severity))

    def read(self, data: Any) -> ProjectSpec:
        if isinstance(data, list):
            project = ProjectSpec(self.source, "nodes")
            project.definitions = self.definitions(data)
            return project
        if not isinstance(data, dict):
            self.problem(f"expected a JSON object or array, found {type(data).__name__}", line=1)
            return ProjectSpec(self.source, "unknown")
        if isinstance(data.get("data"), dict) and "trees" in data["data"]:
            project = self.project(data["data"])
            project.kind = "desktop"
            return project
        if "trees" in data:
            return self.project(data)
        if "nodes" in data and "root" in data:
            if isinstance(data["root"], dict):
                return self.unsupported_dialect()
            project = ProjectSpec(self.source, "tree")
            tree = self.tree(data, index=0)
            if tree is not None:
                project.trees.append(tree)
                project.selected_tree = tree.id
            project.definitions = self.definitions(data.get("custom_nodes") or [])
            return project
        if isinstance(data.get("root"), dict):
            return self.unsupported_dialect()
        self.problem("not a behavior3editor export: expected a project (with 'trees'), a tree "
                     "(with 'root' and 'nodes'), or an array of node definitions", line=1)
        return ProjectSpec(self.source, "unknown")

    def unsupported_dialect(self) -> ProjectSpec:
        self.problem("this is the 'behavior3 v1' format (nodes nested under root.children); "
                     "only behavior3editor 0.3.0 exports are supported", line=1)
        return ProjectSpec(self.source, "unknown")

    def project(self, data: dict[str, Any]) -> ProjectSpec:
        project = ProjectSpec(self.source, "project")
        trees = data.get("trees")
        if not isinstance(trees, list):
            self.problem("'trees' must be an array of trees", line=self.lines.of_key("trees"),
                         key="trees")
            trees = []
        seen: dict[str, TreeSpec] = {}
        for index, raw in enumerate(trees):
            tree = self.tree(raw, index)
            if tree is None:
                continue
            if tree.id in seen:
                self.problem(f"tree id {tree.id!r} is used by two trees", line=tree.line,
                             tree=tree, key="id")
                continue
            seen[tree.id] = tree
            project.trees.append(tree)
        selected = data.get("selectedTree")
        if selected is not None and not isinstance(selected, str):
            self.problem("'selectedTree' must be a tree id or null", key="selectedTree",
                         line=self.lines.of_key("selectedTree"))
            selected = None
        project.selected_tree = selected
        project.definitions = self.definitions(data.get("custom_nodes") or [])
        return project

    def tree(self, raw: Any, index: int) -> TreeSpec | None:
        if not isinstance(raw, dict):
            self.problem(f"tree #{index + 1} is not a JSON object")
            return None
        tree_id = raw.get("id")
        if not isinstance(tree_id, str) or not tree_id:
            tree_id = f"tree-{index + 1}"
            if raw.get("scope") != "tree" or "id" in raw:
                self.problem(f"tree #{index + 1} has no 'id'", key="id")
        title = _text(raw.get("title"))
        root = raw.get("root")
        tree = TreeSpec(tree_id, title, _text(raw.get("description")),
                        root if isinstance(root, str) and root else None,
                        _object(raw.get("properties")), {}, self.lines.of_id(tree_id))
        nodes = raw.get("nodes")
        if not isinstance(nodes, dict):
            self.problem("'nodes' must be an object mapping node ids to nodes", tree=tree,
                         line=tree.line, key="nodes")
            nodes = {}
        for key, node in nodes.items():
            spec = self.node(key, node, tree)
            if spec is not None:
                tree.nodes[key] = spec
        return tree

    def node(self, key: str, raw: Any, tree: TreeSpec) -> NodeSpec | None:
        line = self.lines.of_key(key)
        if not isinstance(raw, dict):
            self.problem("a node must be a JSON object", tree=tree, node=key, line=line)
            return None
        title = _text(raw.get("title"))
        node_id = raw.get("id", key)
        if node_id != key:
            self.problem(f"node is stored under key {key!r} but its 'id' is {node_id!r}",
                         tree=tree, node=key, title=title, line=line, key="id")
        name = raw.get("name")
        if not isinstance(name, str) or not name:
            self.problem("node has no 'name' (the node type)", tree=tree, node=key, title=title,
                         line=line, key="name")
            name = ""
        children: list[str] = []
        if "children" in raw:
            value = raw["children"]
            if isinstance(value, list) and all(isinstance(c, str) for c in value):
                children = list(value)
            else:
                self.problem("'children' must be an array of node ids", tree=tree, node=key,
                             title=title, line=line, key="children")
        if raw.get("child") is not None:
            value = raw["child"]
            if not isinstance(value, str):
                self.problem("'child' must be a node id", tree=tree, node=key, title=title,
                             line=line, key="child")
            elif children:
                self.problem("node has both 'child' and 'children'", tree=tree, node=key,
                             title=title, line=line, key="child")
            else:
                children = [value]
        properties = raw.get("properties", {})
        if not isinstance(properties, dict):
            self.problem("'properties' must be an object", tree=tree, node=key, title=title,
                         line=line, key="properties")
            properties = {}
        shape = "composite" if "children" in raw else "decorator" if "child" in raw else "leaf"
        return NodeSpec(key, name, title or name, _text(raw.get("description")), properties,
                        children, line, shape)

    def definitions(self, raw: Any) -> list[NodeDefinition]:
        if not isinstance(raw, list):
            self.problem("'custom_nodes' must be an array", key="custom_nodes",
                         line=self.lines.of_key("custom_nodes"))
            return []
        result = []
        for index, item in enumerate(raw):
            name = item.get("name") if isinstance(item, dict) else None
            if not isinstance(name, str) or not name:
                self.problem(f"custom node #{index + 1} has no 'name'", key="custom_nodes")
                continue
            assert isinstance(item, dict)
            result.append(NodeDefinition(name, _text(item.get("category")),
                                         _text(item.get("title")) or name,
                                         _object(item.get("properties")),
                                         self.lines.of_id(name)))
        return result


def parse_project(text: str, source: str = "<string>") -> ProjectSpec:
    """Read an export from ``text``. Raises :class:`TreeLoadError` naming every problem."""
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise TreeLoadError([Problem(f"malformed JSON: {exc.msg}", source, exc.lineno,
                                     exc.colno)]) from None
    reader = _Reader(text, source)
    project = reader.read(data)
    errors = [p for p in reader.problems if p.is_error]
    if errors:
        raise TreeLoadError(reader.problems)
    project.problems = reader.problems
    return project


def read_project(path: str | Path) -> ProjectSpec:
    """Read an export file. Raises :class:`TreeLoadError` (also for an unreadable file)."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
        raise TreeLoadError([Problem(f"cannot read the file: {reason}", str(path))]) from None
    return parse_project(text, str(path))


def _text(value: Any) -> str:
    return value if isinstance(value, str) else ""


def _object(value: Any) -> dict[str, Any]:
    return value if isinstance(value, dict) else {}
