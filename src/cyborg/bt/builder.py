"""Turning a parsed project into a tree of live nodes.

* The root is the tree picked by the user (id or title), else the project's ``selectedTree``,
  else the only tree that no other tree references.
* A node whose ``name`` is the id of a tree in the project is a **subtree reference**. Each
  reference builds a fresh instance of that tree, so a tree used twice has two independent sets
  of nodes and memories. Nodes inside a reference get the stable id ``"<ref id>/<node id>"``
  (nested references add more prefixes). A cycle of references is an error naming the trees.
* Every other node is looked up in the :class:`~cyborg.bt.registry.NodeRegistry`; its
  properties are checked against the class's signature and passed to its constructor.
* A composite's ``services`` property declares the services attached to it
  (:mod:`cyborg.bt.service_binding`); they are returned beside the root, for the tree.
* With ``stub_missing``, a stub stands in for each node without a class, and for each node
  whose :attr:`~cyborg.bt.node.Node.requires` names a resource the blackboard lacks.
* The caps of :class:`~cyborg.bt.limits.Limits` hold while building. A node deeper than
  ``max_depth`` levels (the root tree's own node is level 1, each subtree reference adds one) is
  an error and nothing below it is built, so neither building nor ticking can exhaust the
  stack. The instances a tree would make are counted on the specs first
  (:mod:`cyborg.bt.expansion`) and a tree over ``max_nodes`` is refused before any of it is
  built, so doubled references cannot take the memory and time of 2^n copies (building counts
  too, as a second line). A property value nested deeper than
  :data:`~cyborg.bt.limits.MAX_VALUE_DEPTH` is an error naming the property.
* With ``check_all`` (``check_file``) every tree of the project is built once: a reference to a
  tree built already is not expanded again, and its depth is taken from the count above.

Every problem found is collected, and :class:`~cyborg.bt.problems.TreeLoadError` lists them all.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from typing_extensions import override

from cyborg.bt import service_binding as attaching
from cyborg.bt.blackboard import Blackboard
from cyborg.bt.definitions_check import check_definitions
from cyborg.bt.editor_format import NodeDefinition, NodeSpec, ProjectSpec, TreeSpec
from cyborg.bt.editor_v1_names import REPLACED_IN_CYBORG
from cyborg.bt.expansion import Size, measure
from cyborg.bt.limits import MAX_VALUE_DEPTH, Limits, nesting_exceeds
from cyborg.bt.node import Category, Node, TickRecord
from cyborg.bt.ports import bind_ports
from cyborg.bt.problems import Problem, Severity, shown
from cyborg.bt.properties import bind
from cyborg.bt.registry import NodeRegistry
from cyborg.bt.service_registry import ServiceRegistry, default_service_registry
from cyborg.bt.service_runner import ScheduledService
from cyborg.bt.specs import choose_tree
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

    @override
    def tick(self) -> Status:
        return self.children[0].execute()

    def check(self) -> list[str]:
        """One problem unless the instance holds exactly one root node."""
        return [] if len(self.children) == 1 else ["a subtree needs exactly one root node"]


@dataclass
class BuildResult:
    """What :func:`build` returns."""

    root: Subtree | None
    """The chosen tree's instance; ``None`` if none was chosen or it was too big."""
    tree: TreeSpec | None
    """The chosen tree's spec; ``None`` if none could be chosen."""
    problems: list[Problem]
    """Every problem found, errors and warnings; with an error, ``root`` is incomplete."""
    services: list[ScheduledService]
    """The services the chosen tree's composites declare (``services`` property)."""


class _TooManyNodesError(Exception):
    """Raised by the builder at the ``max_nodes``-th + 1 instance, to stop at once."""

    def __init__(self, tree: TreeSpec, spec: NodeSpec | None) -> None:
        super().__init__(tree.id)
        self.tree, self.spec = tree, spec


class _Builder:
    def __init__(self, project: ProjectSpec, registry: NodeRegistry, blackboard: Blackboard,
                 record: TickRecord, stub_missing: Status | None, limits: Limits,
                 services: ServiceRegistry | None = None) -> None:
        self.project = project
        self.service_registry = services  # made when a file first declares a service
        self.services: list[ScheduledService] = []
        self.limits = limits
        self.count = 0
        """Node instances built so far, for ``max_nodes``."""
        self.sizes: dict[str, Size] = {}  # measured by build, once the tree is chosen
        self.built: set[str] = set()
        """Ids of the trees instantiated so far."""
        self.shallow = False
        """Checking a project's other trees: a reference to a tree already built is not
        expanded again (its problems are known; its size comes from :attr:`sizes`)."""
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

    def counted(self, tree: TreeSpec, spec: NodeSpec | None) -> None:
        """Counts one more instance; past ``max_nodes``, stops the whole build."""
        self.count += 1
        if self.count > self.limits.max_nodes:
            raise _TooManyNodesError(tree, spec)

    def too_deep(self, tree: TreeSpec, spec: NodeSpec, level: int) -> bool:
        """Whether a node at ``level`` (its deepest) is past ``max_depth``; if so, reports it."""
        limits = self.limits
        if level <= limits.max_depth:
            return False
        self.report(f"the tree is nested more deeply than {limits.max_depth} levels (the root "
                    "tree's own node is level 1 and each subtree reference adds one), which "
                    f"could exhaust Python's stack when ticked; {limits.how_to_raise('max_depth')}",
                    tree, spec, "name" if spec.name in self.trees else "children")
        return True

    def properties_too_deep(self, tree: TreeSpec, spec: NodeSpec | None,
                            properties: dict[str, object]) -> bool:
        """Reports each property whose value nests deeper than MAX_VALUE_DEPTH."""
        deep = [key for key, value in properties.items()
                if nesting_exceeds(value, MAX_VALUE_DEPTH)]
        for key in deep:
            self.report(f"property {key!r} nests lists or objects more than {MAX_VALUE_DEPTH} "
                        "levels deep", tree, spec, key)
        return bool(deep)

    # ------------------------------------------------------------------ trees
    def instance(self, tree: TreeSpec, uid: str, prefix: str, depth: int,
                 stack: tuple[TreeSpec, ...], title: str, outer_uid: str,
                 level: int = 1, expand: bool = True) -> Subtree:
        """A Subtree node at ``level`` for one instance of ``tree``; with ``expand``, all below."""
        self.counted(tree, None)
        self.built.add(tree.id)
        properties = {} if self.properties_too_deep(tree, None, tree.properties) \
            else tree.properties
        holder = Subtree()
        holder.tree_id = tree.id
        holder.tree_title = tree.title
        holder.bind(uid=uid, node_id=uid.rsplit("/", 1)[-1], name=tree.id, title=title,
                    label=title, description=tree.description, properties=properties,
                    tree_uid=outer_uid, subtree_depth=max(depth - 1, 0),
                    blackboard=self.blackboard, record=self.record)
        if not expand:
            return holder
        if tree.root is None:
            self.report("tree has no root: nothing is connected to its Root block", tree,
                        field="root")
            return holder
        if tree.root not in tree.nodes:
            self.report(f"root {tree.root!r} is not a node of this tree", tree, field="root")
            return holder
        reached: set[str] = set()
        root = self.node(tree, tree.root, prefix, max(depth, 0), stack, (), reached, uid,
                         level + 1)
        for node_id in tree.nodes.keys() - reached:
            self.report("node is not connected to the tree and is ignored", tree,
                        tree.nodes[node_id], severity=Severity.WARNING)
        if root is not None:
            holder.adopt([root])
        return holder

    # ------------------------------------------------------------------ nodes
    def node(self, tree: TreeSpec, node_id: str, prefix: str, depth: int,
             stack: tuple[TreeSpec, ...], path: tuple[str, ...], reached: set[str],
             tree_uid: str, level: int) -> Node | None:
        spec = tree.nodes[node_id]
        reached.add(node_id)
        if self.too_deep(tree, spec, level):
            _reach_below(tree, spec, reached)
            return None
        if spec.name in self.trees:
            return self.reference(tree, spec, prefix, depth, stack, tree_uid, level)
        self.counted(tree, spec)
        node = None if self.properties_too_deep(tree, spec, spec.properties) \
            else self.construct(tree, spec)
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
                                  reached, tree_uid, level + 1)
                if child is not None:
                    children.append(child)
        if node is None:
            return None
        node.bind(uid=prefix + spec.id, node_id=spec.id, name=spec.name, title=spec.title,
                  label=spec.label, description=spec.description, properties=spec.properties,
                  tree_uid=tree_uid, subtree_depth=depth, blackboard=self.blackboard,
                  record=self.record)
        self.wire(tree, spec, node)
        if attaching.SERVICES in spec.properties and not attaching.owns_services(type(node)):
            self.attach(tree, spec, node)
        if len(children) == len(spec.children):
            node.adopt(children)
            for message in node.check():
                self.report(message, tree, spec)
        return node

    def wire(self, tree: TreeSpec, spec: NodeSpec, node: Node) -> None:
        """Binds the file's input/output keys to the node's ports (see :mod:`cyborg.bt.ports`).

        A stub is checked against the ports its definition declares.
        """
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

    def attach(self, tree: TreeSpec, spec: NodeSpec, node: Node) -> None:
        """Attaches the services the node's ``services`` property declares (or reports)."""
        if self.service_registry is None:
            self.service_registry = default_service_registry()
        attached, problems = attaching.attach_services(spec.properties[attaching.SERVICES], node,
                                                       self.service_registry, self.blackboard)
        for message in problems:
            self.report(message, tree, spec, attaching.SERVICES)
        if self.stub_missing is not None:  # as nodes get stubs: left out, with a warning
            attached, left_out = attaching.without_unprovided(attached, self.blackboard.resources)
            for message in left_out:
                self.report(message, tree, spec, attaching.SERVICES, Severity.WARNING)
        self.services.extend(attached)

    def reference(self, tree: TreeSpec, spec: NodeSpec, prefix: str, depth: int,
                  stack: tuple[TreeSpec, ...], outer_uid: str, level: int) -> Node | None:
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
        expand = not (self.shallow and target.id in self.built)
        if not expand and self.too_deep(tree, spec, level - 1 + self.sizes[target.id].levels):
            return None
        return self.instance(target, uid, uid + "/", depth + 1, (*stack, target), title,
                             outer_uid, level, expand)

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
        absent = [key for key in node_type.requires if key not in self.blackboard.resources]
        if absent and self.stub_missing is not None:
            needs = " and ".join(repr(key) for key in absent)
            self.report(f"node {spec.name!r} needs a {needs} resource and this tree has none; a "
                        "stub stands in", tree, spec, "name", Severity.WARNING)
            same_kind = NodeDefinition(spec.name, node_type.category.value, spec.title, {})
            return stub_class(spec, same_kind, self.stub_missing)()
        properties = attaching.without_services(node_type.cls, spec.properties)
        binding = bind(node_type.signature, properties, spec.arg_names)
        for level, said in ((Severity.WARNING, binding.warnings), (Severity.NOTE, binding.notes)):
            for field, message in said:
                self.report(message, tree, spec, field, level)
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
          stub_missing: Status | None = None, check_all: bool = False,
          limits: Limits | None = None, services: ServiceRegistry | None = None) -> BuildResult:
    """Builds the chosen tree (and every tree it references) into live nodes.

    With ``check_all`` every other tree in the project is also built, to find its problems;
    only the chosen tree is returned. Problems of both severities are in the result.
    ``limits`` (default: :meth:`Limits.resolve() <cyborg.bt.limits.Limits.resolve>`) caps
    the depth and the number of instances of each tree built. ``services`` (default:
    :func:`~cyborg.bt.service_registry.default_service_registry`) resolves the composites'
    ``services`` declarations.
    """
    builder = _Builder(project, registry, Blackboard() if blackboard is None else blackboard,
                       TickRecord() if record is None else record, stub_missing,
                       limits if limits is not None else Limits.resolve(source=project.source),
                       services)
    builder.problems.extend(project.problems)
    chosen, reason = choose_tree(project, tree)
    builder.sizes = measure(project, builder.limits.max_nodes, None if check_all else chosen)
    root = None
    if chosen is None:
        if project.kind != "nodes" or tree is not None or not check_all:
            builder.report(reason, field="selectedTree")
    else:
        root = _build_top(builder, chosen)
    attached = list(builder.services)
    if check_all:
        # Each other tree is built once, without expanding again the subtrees built already,
        # so checking costs time in proportion to the file, not to the instances it makes.
        builder.shallow = True
        for other in project.trees:
            if other.id not in builder.built:  # the chosen tree too, if it was too big
                _build_top(builder, other)
        builder.problems.extend(check_definitions(project, registry, stub_missing is not None))
    return BuildResult(root, chosen, builder.problems, attached)


def _build_top(builder: _Builder, tree: TreeSpec) -> Subtree | None:
    """One top-level instance of ``tree``; None when it has more than ``max_nodes``."""
    limits = builder.limits
    builder.count = 0
    if builder.sizes[tree.id].nodes > limits.max_nodes:
        _too_many(builder, tree, None)
        if not builder.shallow:
            return None
    try:
        return builder.instance(tree, tree.id, "", 0, (tree,), tree.title, tree.id)
    except _TooManyNodesError as exc:  # the count above missed some: a safety net
        _too_many(builder, exc.tree, exc.spec)
        return None


def _too_many(builder: _Builder, tree: TreeSpec, spec: NodeSpec | None) -> None:
    limits = builder.limits
    builder.report(f"the tree expands to more than {limits.max_nodes:,} node instances (each "
                   "use of a subtree builds its own copy of it); "
                   f"{limits.how_to_raise('max_nodes')}", tree, spec, "root")


def _reach_below(tree: TreeSpec, spec: NodeSpec, reached: set[str]) -> None:
    """Marks the nodes below ``spec`` in its tree as reached, without recursion."""
    pending = list(spec.children)
    while pending:
        node_id = pending.pop()
        if node_id in tree.nodes and node_id not in reached:
            reached.add(node_id)
            pending.extend(tree.nodes[node_id].children)


def _kwargs(kwargs: dict[str, object]) -> str:
    return ", ".join(f"{key}={shown(value)}" for key, value in kwargs.items())
