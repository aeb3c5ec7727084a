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
Two older forms load with a warning: a tree without ``id`` (early exports) gets one derived
from its title, else the file name, made unique; settings under ``parameters`` (the older name
of ``properties``) are used, with ``properties`` winning where both set a key.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from cyborg.bt.editor_v1 import V1Reader, is_v1, is_v1_definitions, parse_definitions
from cyborg.bt.files import FileRefusedError, decode_json, read_text
from cyborg.bt.json_text import TextLines, first_lines
from cyborg.bt.limits import Limits
from cyborg.bt.problems import Problem, Severity, TreeLoadError, shown
from cyborg.bt.specs import NodeDefinition, NodeSpec, ProjectSpec, TreeSpec, render_title

__all__ = ["NodeDefinition", "NodeSpec", "ProjectSpec", "TreeSpec", "parse_project",
           "read_project", "render_title"]

class _Lines:
    """Line numbers of object keys and ``"id"`` values in the raw JSON text."""

    def __init__(self, text: str) -> None:
        lines = TextLines(text)
        self._keys = first_lines(text, r'"((?:[^"\\]|\\.)*)"\s*:\s*\{', lines)
        self._ids = first_lines(text, r'"(?:id|name)"\s*:\s*"((?:[^"\\]|\\.)*)"', lines)

    def of_key(self, key: str) -> int | None:
        return self._keys.get(key, self._ids.get(key))

    def of_id(self, value: str) -> int | None:
        return self._ids.get(value, self._keys.get(value))


class _Reader:
    def __init__(self, text: str, source: str) -> None:
        self.source = source
        self.lines = _Lines(text)
        self.problems: list[Problem] = []
        self._derived_tree_ids: set[str] = set()

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
            project = ProjectSpec(self.source, "tree")
            tree = self.tree(data, index=0)
            if tree is not None:
                project.trees.append(tree)
                project.selected_tree = tree.id
            project.definitions = self.definitions(data.get("custom_nodes") or [])
            return project
        self.problem("not a behavior3editor export: expected a project (with 'trees'), a tree "
                     "(with 'root' and 'nodes' or, for 1.x, the root node), or an array of node "
                     "definitions", line=1)
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
            self.problem(f"tree #{index + 1} is not a JSON object", key="trees",
                         line=self.lines.of_key("trees"))
            return None
        title = _text(raw.get("title"))
        nodes = raw.get("nodes")
        tree_id = raw.get("id")
        derived_from = ""
        if tree_id is None or tree_id == "":
            # Early behavior3editor exports (behavior3py's test fixture is one) have no id, and
            # behavior3js loads them. Derive one from the title, else the file name, else the
            # position; make it unique against the ids derived so far and against every id and
            # name in the file, so that no node named like it becomes a reference to it.
            base, derived_from = (
                (title.strip(), "its title") if title.strip()
                else (Path(self.source).stem, "the file name")
                if self.source and not self.source.startswith("<")
                else (f"tree-{index + 1}", "its position in the file"))
            # the ids derived so far live on this reader, created on first use
            derived = self._derived_tree_ids
            tree_id, copy = base, 1
            while tree_id in derived or self.lines.of_id(tree_id) is not None:
                copy += 1
                tree_id = f"{base} ({copy})"
            derived.add(tree_id)
        elif not isinstance(tree_id, str):
            self.problem(f"tree #{index + 1}: 'id' must be a string, not {shown(tree_id)}",
                         key="id")
            tree_id = f"tree-{index + 1}"
        # With no id in the file, point at the tree's first node: the nearest known line.
        line = self.lines.of_id(tree_id) if not derived_from else min(
            (n for key in (nodes if isinstance(nodes, dict) else {})
             if (n := self.lines.of_key(key)) is not None), default=None)
        properties, found = _settings(raw)
        root = raw.get("root")
        tree = TreeSpec(tree_id, title, _text(raw.get("description")),
                        root if isinstance(root, str) and root else None,
                        properties, {}, line)
        if derived_from:
            self.problem(f"tree has no 'id' (an early behavior3editor export); using "
                         f"{tree_id!r}, derived from {derived_from}. Other trees cannot "
                         "reference it as a subtree", tree=tree, line=line, key="id",
                         severity=Severity.WARNING)
        for severity, field_name, message in found:
            self.problem(message, tree=tree, line=line, key=field_name, severity=severity)
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
            self.problem(f"node is stored under key {key!r} but its 'id' is {shown(node_id)}",
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
        properties, found = _settings(raw)
        for severity, field_name, message in found:
            self.problem(message, tree=tree, node=key, title=title, line=line, key=field_name,
                         severity=severity)
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


def parse_project(text: str, source: str = "<string>", path: Path | None = None, *,
                  limits: Limits | None = None) -> ProjectSpec:
    """Parses an export from ``text`` into a project.

    The export is behavior3editor 0.3.0's, or a 1.x tree file or node definitions
    (:mod:`cyborg.bt.editor_v1`, which finds the files it references from ``path`` and charges
    them to ``limits``). Raises :class:`TreeLoadError` naming every problem when one is an
    error; warnings stay in the project's ``problems``.
    """
    text = text.removeprefix("\ufeff")
    limits = limits if limits is not None else Limits.resolve(source=source)
    data = decode_json(text, source, limits)
    problems: list[Problem]
    if is_v1(data):
        reader_v1 = V1Reader(source, path, limits)
        project = reader_v1.read(data, text)
        problems = reader_v1.problems
    elif is_v1_definitions(data):
        project = ProjectSpec(source, "nodes")
        project.definitions, problems = parse_definitions(data, source, text)
    else:
        reader = _Reader(text, source)
        project = reader.read(data)
        problems = reader.problems
    if any(p.is_error for p in problems):
        raise TreeLoadError(problems)
    project.problems = problems
    return project


def read_project(path: str | Path, *, limits: Limits | None = None) -> ProjectSpec:
    """Reads and parses an export file, as :func:`parse_project` does.

    Raises :class:`TreeLoadError`, also for a file that cannot or may not be read (see
    :mod:`cyborg.bt.files`). ``limits`` default to
    :meth:`Limits.resolve() <cyborg.bt.limits.Limits.resolve>`.
    """
    path = Path(path)
    limits = limits if limits is not None else Limits.resolve(source=str(path))
    try:
        text = read_text(path, limits)
    except FileRefusedError as exc:
        raise TreeLoadError([Problem(exc.reason, str(path), exc.line,
                                     field=None if exc.line else "file")]) from None
    return parse_project(text, str(path), path, limits=limits)


def _text(value: Any) -> str:
    return value if isinstance(value, str) else ""


def _object(value: Any) -> dict[str, Any]:
    return value if isinstance(value, dict) else {}


def _settings(raw: dict[str, Any]) -> tuple[dict[str, Any], list[tuple[Severity, str, str]]]:
    """A node's or tree's settings: its ``properties``, completed from ``parameters``.

    ``parameters`` is the older name of ``properties`` (behavior3js still dumps both, and
    behavior3py's test fixture has both). When ``properties`` is missing or empty, a non-empty
    ``parameters`` object *is* the settings; when both have keys, ``properties`` wins and only
    the keys it lacks are taken from ``parameters``. Returns the settings and what to report,
    as ``(severity, field, message)``: a warning for each use of ``parameters`` (and for each of
    its values that ``properties`` overrides), an error when either is not a JSON object.
    """
    found: list[tuple[Severity, str, str]] = []
    properties = raw.get("properties", {})
    if not isinstance(properties, dict):
        found.append((Severity.ERROR, "properties", "'properties' must be an object"))
        properties = {}
    parameters = raw.get("parameters", {})
    if not isinstance(parameters, dict):
        found.append((Severity.ERROR, "parameters",
                      "'parameters' (the older name of 'properties') must be an object"))
        return properties, found
    if not properties and parameters:
        keys = ", ".join(repr(key) for key in parameters)
        found.append((Severity.WARNING, "parameters",
                      "settings are under 'parameters', the older name of 'properties'; "
                      f"using them: {keys}"))
        return dict(parameters), found
    merged = dict(properties)
    for key, value in parameters.items():
        if key not in properties:
            merged[key] = value
            found.append((Severity.WARNING, "parameters",
                          f"{key!r} is taken from 'parameters' (the older name of "
                          "'properties'), as 'properties' does not set it"))
        elif properties[key] != value:
            found.append((Severity.WARNING, "parameters",
                          f"{key!r} under 'parameters' ({shown(value)}) is ignored: 'properties' "
                          f"sets it to {shown(properties[key])}"))
    return merged, found
