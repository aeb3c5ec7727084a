"""Turning a parsed project into a tree of live nodes.

* The root is the tree picked by the user (id or title), else the project's ``selectedTree``,
  else the only tree that no other tree references.
* A node whose ``name`` is the id of a tree in the project is a **subtree reference**. Each
  reference builds a fresh instance of that tree, so a tree used twice has two independent sets
  of nodes and memories. Nodes inside a reference get the stable id ``"<ref id>/<node id>"``
  (nested references add more prefixes). A cycle of references is an error naming the trees.
* Every other node is looked up in the :class:`~cyborg.bt.registry.NodeRegistry`; its
  properties are checked against the class's signature and passed to its constructor.
* With ``stub_missing``, a stub stands in for each node without a class, and for each node
  whose :attr:`~cyborg.bt.node.Node.requires` names a resource the blackboard lacks.

Every problem found is collected, and :class:`~cyborg.bt.problems.TreeLoadError` lists them all.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from cyborg.bt.blackboard import Blackboard
from cyborg.bt.editor_format import NodeDefinition, NodeSpec, ProjectSpec, TreeSpec
from cyborg.bt.editor_v1_names import REPLACED_IN_CYBORG
from cyborg.bt.node import Category, Node, TickRecord
from cyborg.bt.ports import bind_ports
from cyborg.bt.problems import Problem, Severity
from cyborg.bt.properties import bind
from cyborg.bt.registry import NodeRegistry
from cyborg.bt.status import Status
from cyborg.bt.stubs import stub_class


class Subtree(Node):
    """A tree instance in the running tree: the root tree, or a subtree reference.

    It ticks the referenced tree's root and returns its status. It shows up in snapshots and
    the structure with category ``tree``, so the nesting of trees stays visible.
    """

    category = Category.TREE
    tree_id: str = ""
    """Id of the tree this instance was built from."""
    tree_title: str = ""

    def tick(self) -> Status:
        return self.children[0].execute()

    def check(self) -> list[str]:
        return [] if len(self.children) == 1 else ["a subtree needs exactly one root node"]


@dataclass
class BuildResult:
    root: Subtree | None
    tree: TreeSpec | None
    problems: list[Problem]


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


class _Builder:
    def __init__(self, project: ProjectSpec, registry: NodeRegistry, blackboard: Blackboard,
                 record: TickRecord, stub_missing: Status | None) -> None:
        self.project = project
        self.registry = registry
        self.blackboard = blackboard
        self.record = record
        self.stub_missing = stub_missing
        self.trees = project.tree_by_id()
        self.definitions = {d.name: d for d in project.definitions}
        self.problems: list[Problem] = []
        self._seen: set[tuple[str | None, str | None, str]] = set()

    def report(self, message: str, tree: TreeSpec | None = None, spec: NodeSpec | None = None,
               field: str | None = None, severity: Severity = Severity.ERROR) -> None:
        key = (tree.id if tree else None, spec.id if spec else None, message)
        if key in self._seen:  # a tree built twice reports its problems once
            return
        self._seen.add(key)
        line = spec.line if spec else (tree.line if tree else None)
        source = tree.source if tree and tree.source else self.project.source
        self.problems.append(Problem(
            message, source, line, None, tree.display_name if tree else None,
            spec.id if spec else None, spec.label if spec else None, field, severity))

    # ------------------------------------------------------------------ trees
    def instance(self, tree: TreeSpec, uid: str, prefix: str, depth: int,
                 stack: tuple[TreeSpec, ...], title: str, outer_uid: str) -> Subtree:
        """A Subtree node for one instance of ``tree`` and everything below it."""
        holder = Subtree()
        holder.tree_id = tree.id
        holder.tree_title = tree.title
        holder.bind(uid=uid, node_id=uid.rsplit("/", 1)[-1], name=tree.id, title=title,
                    label=title, description=tree.description, properties=tree.properties,
                    tree_uid=outer_uid, subtree_depth=max(depth - 1, 0),
                    blackboard=self.blackboard, record=self.record)
        if tree.root is None:
            self.report("tree has no root: nothing is connected to its Root block", tree,
                        field="root")
            return holder
        if tree.root not in tree.nodes:
            self.report(f"root {tree.root!r} is not a node of this tree", tree, field="root")
            return holder
        reached: set[str] = set()
        root = self.node(tree, tree.root, prefix, max(depth, 0), stack, (), reached, uid)
        for node_id in tree.nodes.keys() - reached:
            self.report("node is not connected to the tree and is ignored", tree,
                        tree.nodes[node_id], severity=Severity.WARNING)
        if root is not None:
            holder.adopt([root])
        return holder

    # ------------------------------------------------------------------ nodes
    def node(self, tree: TreeSpec, node_id: str, prefix: str, depth: int,
             stack: tuple[TreeSpec, ...], path: tuple[str, ...], reached: set[str],
             tree_uid: str) -> Node | None:
        spec = tree.nodes[node_id]
        reached.add(node_id)
        if spec.name in self.trees:
            return self.reference(tree, spec, prefix, depth, stack, tree_uid)
        node = self.construct(tree, spec)
        children: list[Node] = []
        for child_id in spec.children:
            if child_id not in tree.nodes:
                self.report(f"child {child_id!r} is not a node of this tree", tree, spec,
                            "children")
            elif child_id in path or child_id == node_id:
                self.report(f"child {child_id!r} is also an ancestor (a loop in the tree)",
                            tree, spec, "children")
            elif child_id in reached:
                self.report(f"child {child_id!r} already has another parent", tree, spec,
                            "children")
            else:
                child = self.node(tree, child_id, prefix, depth, stack, (*path, node_id),
                                  reached, tree_uid)
                if child is not None:
                    children.append(child)
        if node is None:
            return None
        node.bind(uid=prefix + spec.id, node_id=spec.id, name=spec.name, title=spec.title,
                  label=spec.label, description=spec.description, properties=spec.properties,
                  tree_uid=tree_uid, subtree_depth=depth, blackboard=self.blackboard,
                  record=self.record)
        self.wire(tree, spec, node)
        if len(children) == len(spec.children):
            node.adopt(children)
            for message in node.check():
                self.report(message, tree, spec)
        return node

    def wire(self, tree: TreeSpec, spec: NodeSpec, node: Node) -> None:
        """Bind the file's input/output keys to the node's ports (see :mod:`cyborg.bt.ports`);
        a stub is checked against the ports its definition declares."""
        cls = type(node)
        declared: tuple[Sequence[str], Sequence[str]] = (cls.inputs, cls.outputs)
        if cls.__module__ == stub_class.__module__:
            definition = self.definitions.get(spec.name)
            if definition is None:
                return
            declared = (definition.inputs, definition.outputs)
        if not (spec.inputs or spec.outputs or declared[0] or declared[1]):
            return
        ports: dict[str, str] = {}
        for direction, ports_declared, keys in (("input", declared[0], spec.inputs),
                                                ("output", declared[1], spec.outputs)):
            bound, errors, ignored = bind_ports(ports_declared, keys, direction)
            ports.update(bound)
            for message in errors:
                self.report(message, tree, spec, direction)
            for message in ignored:
                self.report(message, tree, spec, direction, Severity.WARNING)
        node.ports = ports

    def reference(self, tree: TreeSpec, spec: NodeSpec, prefix: str, depth: int,
                  stack: tuple[TreeSpec, ...], outer_uid: str) -> Node | None:
        target = self.trees[spec.name]
        if spec.children:
            self.report("a subtree reference cannot have children", tree, spec, "children")
        if target in stack:
            cycle = [t.display_name for t in stack[stack.index(target):]]
            chain = " -> ".join(repr(name) for name in [*cycle, target.display_name])
            self.report(f"subtree references form a cycle: {chain}", tree, spec, "name")
            return None
        uid = prefix + spec.id
        title = spec.label if spec.title and spec.title != spec.name else target.title
        return self.instance(target, uid, uid + "/", depth + 1, (*stack, target), title,
                             outer_uid)

    def construct(self, tree: TreeSpec, spec: NodeSpec) -> Node | None:
        if not spec.name:
            return None
        node_type = self.registry.get(spec.name)
        if spec.foreign and node_type is not None and node_type.origin == "stock" \
                and spec.name in REPLACED_IN_CYBORG:
            node_type = None  # cyborg's node of that name means something else
        if node_type is None:
            definition = self.definitions.get(spec.name)
            if self.stub_missing is not None:
                self.report(f"node {spec.name!r} is not implemented; a stub stands in",
                            tree, spec, "name", Severity.WARNING)
                return stub_class(spec, definition, self.stub_missing)()
            where = Path(definition.source).name if definition and definition.source \
                else "custom_nodes"
            declared = f" (declared in {where}, but no Python class is registered for it)" \
                if definition else ""
            if spec.foreign:
                self.report(f"behavior3 v1's {spec.name!r} ({spec.foreign}) has no equivalent "
                            "in cyborg: register a node class named "
                            f"{spec.name!r}, or run with --stub-missing", tree, spec, "name")
                return None
            self.report(f"unknown node name {spec.name!r}{declared}; registered: "
                        f"{', '.join(self.registry.names())}", tree, spec, "name")
            return None
        absent = [key for key in node_type.cls.requires if key not in self.blackboard.resources]
        if absent and self.stub_missing is not None:
            needs = " and ".join(repr(key) for key in absent)
            self.report(f"node {spec.name!r} needs a {needs} resource and this tree has none; a "
                        "stub stands in", tree, spec, "name", Severity.WARNING)
            same_kind = NodeDefinition(spec.name, node_type.category.value, spec.title, {})
            return stub_class(spec, same_kind, self.stub_missing)()
        binding = bind(node_type.signature, spec.properties)
        for field, message in binding.warnings:
            self.report(message, tree, spec, field, Severity.WARNING)
        for field, message in binding.errors:
            self.report(message, tree, spec, field)
        if binding.errors:
            return None
        try:
            return node_type.cls(**binding.kwargs)
        except Exception as exc:
            self.report(f"{node_type.cls.__name__}({_kwargs(binding.kwargs)}) raised "
                        f"{type(exc).__name__}: {exc}", tree, spec)
            return None


def build(project: ProjectSpec, registry: NodeRegistry, *, tree: str | None = None,
          blackboard: Blackboard | None = None, record: TickRecord | None = None,
          stub_missing: Status | None = None, check_all: bool = False) -> BuildResult:
    """Build the chosen tree (and every tree it references) into live nodes.

    With ``check_all`` every other tree in the project is also built, to find its problems;
    only the chosen tree is returned. Problems of both severities are in the result.
    """
    builder = _Builder(project, registry, Blackboard() if blackboard is None else blackboard,
                       TickRecord() if record is None else record,
                       stub_missing)
    builder.problems.extend(project.problems)
    chosen, reason = choose_tree(project, tree)
    root = None
    if chosen is None:
        if project.kind != "nodes" or tree is not None:
            builder.report(reason, field="selectedTree")
    else:
        root = builder.instance(chosen, chosen.id, "", 0, (chosen,), chosen.title, chosen.id)
    if check_all:
        for other in project.trees:
            if other is not chosen:
                builder.instance(other, other.id, "", 0, (other,), other.title, other.id)
        _check_definitions(builder)
    return BuildResult(root, chosen, builder.problems)


def _check_definitions(builder: _Builder) -> None:
    project = builder.project
    # a v1 node-config file is the editor's whole palette: only the nodes used are checked
    used = {node.name for tree in project.trees for node in tree.nodes.values()}
    for definition in project.definitions:
        if project.kind == "v1" and definition.name not in used:
            continue
        node_type = builder.registry.get(definition.name)
        where = Problem("", definition.source or project.source, definition.line,
                        node_title=definition.name)
        if node_type is None:
            if builder.stub_missing is None and project.kind != "v1":  # v1: an error per use
                builder.problems.append(_at(where, f"custom node {definition.name!r} is declared "
                                               "but no Python class is registered for it",
                                            Severity.WARNING))
            continue
        if definition.category and definition.category != node_type.category.value:
            builder.problems.append(_at(
                where, f"custom node {definition.name!r} is declared as a {definition.category}"
                f" but {node_type.cls.__name__} is a {node_type.category.value}",
                Severity.WARNING))


def _at(where: Problem, message: str, severity: Severity) -> Problem:
    return Problem(message, where.source, where.line, None, None, None, where.node_title, None,
                   severity)


def _kwargs(kwargs: dict[str, object]) -> str:
    return ", ".join(f"{key}={value!r}" for key, value in kwargs.items())
