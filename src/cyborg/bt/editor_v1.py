"""Reading behavior3editor 1.x tree files (the maintained editor's "behavior3 v1" format).

One file holds one tree, its nodes nested::

    {"version": "1.8.2", "name": "patrol", "desc": "...", "prefix": "", "export": true,
     "group": [], "import": ["vars/robot.json"], "vars": [{"name": "target", "desc": ""}],
     "root": {"id": "1", "name": "Sequence", "children": [
        {"id": "2", "name": "FindTarget", "output": ["target"]},
        {"id": "3", "name": "Sequence", "path": "trees/approach.json"},
        {"id": "4", "name": "Wait", "args": {"time": 2}, "disabled": true}]}}

How it becomes a :class:`~cyborg.bt.editor_format.ProjectSpec`:

* Files are found relative to the **workdir**, the nearest folder at or above the tree file
  that holds a ``*.b3-workspace`` file (as the editor does), else relative to the tree file's
  own folder. The node definitions come from the workdir's ``node-config.b3-setting``.
* Ids may be integers (before 1.8.2) or strings; they become strings. Node names go through
  :mod:`cyborg.bt.editor_v1_names` (a v1 ``Sequence`` is cyborg's ``MemSequence``; seconds
  become milliseconds). ``args`` are the node's properties, arg defaults from the definitions
  filled in as the editor's build does; ``input``/``output`` bind ports (:mod:`cyborg.bt.ports`).
* A node with ``path`` is a subtree reference: the file it names is read (once) as a tree of
  its own, and each reference builds an independent instance of it. The children the
  referencing file keeps are the editor's cached copy and are ignored.
* ``disabled`` nodes are left out with everything below them, as the editor's build does.
* ``vars`` (``declvar`` in 1.8.0-1.8.1) and the ``vars`` of the ``import`` files declare
  blackboard variables; once any are declared, an input or output naming an undeclared one is
  a warning. ``debug``, ``group``, ``prefix``, ``custom`` and ``$``-keys do not change how a
  tree runs and are ignored.

Every file is read through :mod:`cyborg.bt.files` (regular files only, never blocking) and
charged to the load's byte budget (:class:`~cyborg.bt.limits.Limits`); nesting, counted across
subtree files, stops at ``max_depth`` with a located error, so a chain of files referencing each
other cannot exhaust the stack. Imports are followed without recursion.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

from cyborg.bt.editor_v1_names import EQUIVALENTS, NO_EQUIVALENT, ArgError
from cyborg.bt.files import FileRefusedError, decode_json, read_text
from cyborg.bt.json_text import TextLines, first_lines
from cyborg.bt.limits import Limits
from cyborg.bt.problems import Problem, Severity, TreeLoadError
from cyborg.bt.specs import NodeDefinition, NodeSpec, ProjectSpec, TreeSpec

SETTING_FILE = "node-config.b3-setting"
_ID = re.compile(r'"id"\s*:\s*(?:"((?:[^"\\]|\\.)*)"|(-?\d+))')
_CATEGORIES = ("action", "condition", "decorator", "composite")


def is_v1(data: Any) -> bool:
    """A behavior3 v1 tree: an object whose ``root`` is the root node itself."""
    return isinstance(data, dict) and isinstance(data.get("root"), dict)


def is_v1_definitions(data: Any) -> bool:
    """A ``.b3-setting`` node list: an array of definitions with a ``type``."""
    return isinstance(data, list) and any(isinstance(item, dict) and "type" in item
                                          for item in data)


def find_workdir(tree_file: Path) -> Path:
    """The workdir of ``tree_file``: the folder the files a tree names are relative to.

    That is the nearest folder at or above ``tree_file`` with a ``*.b3-workspace`` (or, lacking
    one, a ``node-config.b3-setting``), else the tree file's own folder.
    """
    start = tree_file.resolve().parent
    for folder in (start, *start.parents):
        if any(folder.glob("*.b3-workspace")) or (folder / SETTING_FILE).is_file():
            return folder
    return start


def parse_definitions(raw: list[Any], source: str, text: str = "") -> tuple[
        list[NodeDefinition], list[Problem]]:
    """Node definitions from a ``.b3-setting`` array, and the problems found in it.

    Each definition takes its category from ``type``, its properties from the args' defaults,
    and its declared input/output ports; an entry without a ``name`` is an error and left out.
    ``text``, the file's text, gives the definitions their lines.
    """
    lines = _LineIndex(text)
    definitions, problems = [], []
    for index, item in enumerate(raw):
        name = item.get("name") if isinstance(item, dict) else None
        if not isinstance(name, str) or not name:
            problems.append(Problem(f"node definition #{index + 1} has no 'name'", source,
                                    field="name"))
            continue
        assert isinstance(item, dict)
        kind = _text(item.get("type")).lower()
        category = next((c for c in _CATEGORIES if kind.startswith(c)), "")
        args = item.get("args")
        defaults = {arg["name"]: arg["default"] for arg in (args if isinstance(args, list) else [])
                    if isinstance(arg, dict) and isinstance(arg.get("name"), str)
                    and "default" in arg}
        definitions.append(NodeDefinition(
            name, category, _text(item.get("desc")) or name, defaults, lines.of_name(name),
            _strings(item.get("input")), _strings(item.get("output")), source))
    return definitions, problems


class _LineIndex:
    """Lines of node ids and definition names in a file's text."""

    def __init__(self, text: str) -> None:
        lines = TextLines(text)
        self._ids = first_lines(text, _ID, lines)
        self._names = first_lines(text, r'"name"\s*:\s*"((?:[^"\\]|\\.)*)"', lines)

    def of_id(self, node_id: str) -> int | None:
        return self._ids.get(node_id)

    def of_name(self, name: str) -> int | None:
        return self._names.get(name)


class V1Reader:
    """Reads one v1 tree file and every file it references into a project."""

    def __init__(self, source: str, path: Path | None, limits: Limits | None = None) -> None:
        self.source = source
        self.path = path
        self.limits = limits if limits is not None else Limits.resolve(source=source)
        self.workdir = find_workdir(path) if path is not None else None
        self.problems: list[Problem] = []
        self.trees: list[TreeSpec] = []
        self._tree_ids: dict[Path, str] = {}
        self._unreadable: set[Path] = set()
        self._declared: set[str] = set()
        self._defaults: dict[str, dict[str, Any]] = {}

    def problem(self, message: str, source: str | None = None, *, line: int | None = None,
                tree: TreeSpec | None = None, node: NodeSpec | None = None,
                field: str | None = None, severity: Severity = Severity.ERROR) -> None:
        """Records a problem in ``source`` (default: the main file), at ``node``'s line if given."""
        self.problems.append(Problem(
            message, source or self.source, line if node is None else node.line, None,
            tree.display_name if tree else None, node.id if node else None,
            node.label if node else None, field, severity))

    # ------------------------------------------------------------------ files
    def read(self, data: dict[str, Any], text: str) -> ProjectSpec:
        """The project of the main tree ``data`` (parsed from ``text``) and the files it names.

        Its problems are collected in :attr:`problems`, for the caller to raise or report.
        """
        project = ProjectSpec(self.source, "v1")
        project.definitions = self.definitions()
        self._defaults = {d.name: d.properties for d in project.definitions}
        self._declared = self.declarations(data, self.source)
        main = self.tree(data, text, self.source, self.path, 0)
        project.trees = self.trees
        project.selected_tree = main.id
        self.check_variables(project)
        return project

    def resolve(self, relative: str) -> Path | None:
        """The path of a file named in the tree; ``None`` if not found or no tree file.

        The name is workdir-relative as the editor writes it, else relative to the tree file's
        folder.
        """
        if self.path is None:
            return None
        folders = [self.workdir, self.path.resolve().parent]
        for folder in dict.fromkeys(f for f in folders if f is not None):
            candidate = folder / relative
            if candidate.exists():  # a FIFO or folder is found here, and refused when read
                return candidate.resolve()
        return None

    def load(self, relative: str, field: str, tree: TreeSpec, node: NodeSpec | None = None,
             ) -> tuple[Path, Any, str] | None:
        """Reads and parses a referenced JSON file; ``None`` and a located problem if it fails."""
        path = self.resolve(relative)
        where = "the workdir or the tree's folder" if self.path else "a file (text given)"
        if path is None:
            self.problem(f"{field} {relative!r} was not found in {where}", tree.source,
                         tree=tree, node=node, line=tree.line, field=field)
            return None
        try:
            text = read_text(path, self.limits)
            return path, decode_json(text, str(path), self.limits), text
        except FileRefusedError as exc:
            self.problem(f"{field} {relative!r}: cannot read {path}: {exc.reason}", tree.source,
                         tree=tree, node=node, line=tree.line, field=field)
        except TreeLoadError as exc:  # located in the file referenced
            self.problems.extend(exc.problems)
        return None

    def definitions(self) -> list[NodeDefinition]:
        """The node definitions of the workdir's ``node-config.b3-setting``.

        Lacking that file, the workdir's only ``*.b3-setting`` file is read. A file that cannot
        be read, or holds no array of definitions, is a warning and gives none.
        """
        if self.workdir is None:
            return []
        setting = self.workdir / SETTING_FILE
        if not setting.exists():
            found = sorted(self.workdir.glob("*.b3-setting"))
            if len(found) != 1:
                return []
            setting = found[0]
        try:
            text = read_text(setting, self.limits)
            raw = decode_json(text, str(setting), self.limits)
        except (FileRefusedError, TreeLoadError) as exc:
            reason = exc.reason if isinstance(exc, FileRefusedError) else exc.problems[0].message
            line = exc.line if isinstance(exc, FileRefusedError) else exc.problems[0].line
            self.problem(f"cannot read the node definitions: {reason}", str(setting),
                         line=line, field="node definitions", severity=Severity.WARNING)
            return []
        if not isinstance(raw, list):
            raw = raw.get("nodes") if isinstance(raw, dict) else None
        if not isinstance(raw, list):
            self.problem("node definitions must be an array", str(setting), line=1,
                         field="node definitions", severity=Severity.WARNING)
            return []
        definitions, problems = parse_definitions(raw, str(setting), text)
        self.problems.extend(problems)
        return definitions

    def declarations(self, data: dict[str, Any], source: str) -> set[str]:
        """Variable names declared by a tree and by the files it imports, and theirs.

        Each file is read once, followed with a work list rather than recursion.
        """
        names: set[str] = set()
        seen: set[Path] = set()
        pending: list[tuple[dict[str, Any], str]] = [(data, source)]
        while pending:
            data, source = pending.pop()
            raw = data.get("vars", data.get("declvar"))
            names |= {item["name"] for item in (raw if isinstance(raw, list) else [])
                      if isinstance(item, dict) and isinstance(item.get("name"), str)}
            holder = TreeSpec(source, _text(data.get("name")), "", None, {}, {}, 1, source)
            for relative in _strings(data.get("import")):
                path = self.resolve(relative)
                if path is not None and path in seen:
                    continue
                loaded = self.load(relative, "import", holder)
                if loaded is not None and isinstance(loaded[1], dict):
                    seen.add(loaded[0])
                    pending.append((loaded[1], str(loaded[0])))
        return names

    # ------------------------------------------------------------------ trees
    def tree(self, data: dict[str, Any], text: str, source: str, path: Path | None,
             depth: int) -> TreeSpec:
        """Reads one tree file whose root sits ``depth`` levels below the main tree's root."""
        tree_id = self.tree_id(path)
        stem = path.stem if path is not None else "tree"
        title = _text(data.get("name")) or stem
        tree = TreeSpec(tree_id, title, _text(data.get("desc")), None, {}, {}, 1,
                        source if source != self.source else "")
        if path is not None:
            self._tree_ids[path.resolve()] = tree_id
        self.trees.append(tree)
        version = _text(data.get("version"))
        if version and not re.match(r"1\.", version):
            self.problem(f"written by behavior3editor {version}; read as a 1.x file", source,
                         line=1, tree=tree, field="version", severity=Severity.WARNING)
        root = self.node(data["root"], tree, _LineIndex(text), source, [0], depth)
        tree.root = root.id if root is not None else None
        return tree

    def tree_id(self, path: Path | None) -> str:
        """The tree id of the file at ``path``: its workdir-relative path without suffix.

        Outside the workdir it is the file's stem; a tree given as text is ``"tree"``.
        """
        if path is None:
            return "tree"
        resolved = path.resolve()
        if self.workdir is not None and resolved.is_relative_to(self.workdir):
            return resolved.relative_to(self.workdir).with_suffix("").as_posix()
        return resolved.with_suffix("").name

    def node(self, raw: Any, tree: TreeSpec, lines: _LineIndex, source: str,
             counter: list[int], depth: int = 0) -> NodeSpec | None:
        """Flattens ``raw`` and its enabled descendants into ``tree.nodes``.

        Returns ``raw``'s spec, or ``None`` when it is left out (not an object, too deep, or its
        id used twice).
        """
        if not isinstance(raw, dict):
            self.problem("a node must be a JSON object", source, tree=tree, field="children")
            return None
        limits = self.limits
        if depth >= limits.max_depth:
            self.problem(f"the tree is nested more deeply than {limits.max_depth} levels "
                         "(counting the files of subtrees as levels); "
                         f"{limits.how_to_raise('max_depth')}", source, tree=tree,
                         line=lines.of_id(str(raw.get("id"))), field="children")
            return None
        counter[0] += 1
        node_id = raw.get("id")
        key = str(node_id) if isinstance(node_id, str | int) and node_id != "" else ""
        line = lines.of_id(key) if key else None
        v1_name = raw.get("name")
        spec = NodeSpec(key or f"#{counter[0]}", v1_name if isinstance(v1_name, str) else "",
                        _text(raw.get("desc")) or _text(v1_name), _text(raw.get("desc")), {},
                        [], line)
        if not key:
            self.problem(f"node has no 'id'; called {spec.id!r} here", source, tree=tree,
                         node=spec, field="id", severity=Severity.WARNING)
        elif key in tree.nodes:
            self.problem(f"node id {key!r} is used twice in this file", source, tree=tree,
                         node=spec, field="id")
            return None
        if not spec.name:
            self.problem("node has no 'name' (the node type)", source, tree=tree, node=spec,
                         field="name")
        args = raw.get("args", {})
        if not isinstance(args, dict):
            self.problem("'args' must be an object", source, tree=tree, node=spec, field="args")
            args = {}
        args = {**self._defaults.get(spec.name, {}), **args}
        spec.inputs = self.keys(raw, "input", tree, spec, source)
        spec.outputs = self.keys(raw, "output", tree, spec, source)
        path = raw.get("path")
        if isinstance(path, str) and path:
            return self.reference(spec, path, tree, source, depth)
        equivalent = EQUIVALENTS.get(spec.name)
        if equivalent is not None:
            spec.name, spec.arg_names = equivalent.name, dict(equivalent.renamed)
            try:
                spec.properties = equivalent.convert(args)
            except ArgError as exc:
                self.problem(str(exc), source, tree=tree, node=spec, field=exc.arg)
        else:
            spec.properties = dict(args)
            spec.foreign = NO_EQUIVALENT.get(spec.name, "")
        children = raw.get("children", [])
        if not isinstance(children, list):
            self.problem("'children' must be an array of nodes", source, tree=tree, node=spec,
                         field="children")
            children = []
        spec.shape = "composite" if len(children) > 1 else "decorator" if children else "leaf"
        tree.nodes[spec.id] = spec
        for child in children:
            if isinstance(child, dict) and child.get("disabled") is True:
                continue
            built = self.node(child, tree, lines, source, counter, depth + 1)
            if built is not None:
                spec.children.append(built.id)
        return spec

    def reference(self, spec: NodeSpec, relative: str, tree: TreeSpec,
                  source: str, depth: int) -> NodeSpec | None:
        """The spec of a node with ``path``, which refers to the subtree file's tree by id.

        The file becomes a tree of the project, read once however many nodes refer to it; if
        it cannot be read, the node's name is left empty.
        """
        spec.title = ""  # the subtree's own name labels it
        tree.nodes[spec.id] = spec
        resolved = self.resolve(relative)
        known = self._tree_ids.get(resolved) if resolved is not None else None
        if known is not None:  # read already: each file is read (and charged) once
            spec.name = known
            return spec
        loaded = None if resolved in self._unreadable else self.load(relative, "path", tree,
                                                                      spec)
        if loaded is None:  # reported at the first reference to it
            if resolved is not None:
                self._unreadable.add(resolved)
            spec.name = ""
            return spec
        path, data, text = loaded
        known = self._tree_ids.get(path)
        if known is None:
            if not is_v1(data):
                self._unreadable.add(path)
                self.problem(f"path {relative!r}: {path} is not a behavior3 v1 tree file",
                             source, tree=tree, node=spec, field="path")
                spec.name = ""
                return spec
            known = self.tree(data, text, str(path), path, depth + 1).id
        spec.name = known
        return spec

    def keys(self, raw: dict[str, Any], field: str, tree: TreeSpec, spec: NodeSpec,
             source: str) -> list[str]:
        """The variable names in ``raw[field]`` (``null``: unbound, ``""``); a problem if not."""
        value = raw.get(field, [])
        if not isinstance(value, list) or not all(k is None or isinstance(k, str)
                                                  for k in value):
            self.problem(f"'{field}' must be an array of blackboard variable names (or null "
                         "for an unbound port)", source, tree=tree, node=spec, field=field)
            return []
        return ["" if key is None else key for key in value]

    def check_variables(self, project: ProjectSpec) -> None:
        """Once variables are declared, every input and output must name one of them."""
        if not self._declared:
            return
        for tree in project.trees:
            for spec in tree.nodes.values():
                for field, keys in (("input", spec.inputs), ("output", spec.outputs)):
                    for key in keys:
                        if key and key not in self._declared:
                            self.problem(f"{field} {key!r} is not a declared variable (vars, "
                                         "or the vars of an imported file)",
                                         tree.source or self.source, tree=tree, node=spec,
                                         field=field, severity=Severity.WARNING)


def _text(value: Any) -> str:
    return value if isinstance(value, str) else ""


def _strings(value: Any) -> list[str]:
    return [item for item in value if isinstance(item, str)] if isinstance(value, list) else []
