"""One-call entry points: load a tree file and get a :class:`~cyborg.bt.tree.Tree` to tick.

    from cyborg.bt import load_tree

    tree = load_tree("patrol.b3.json")             # the file's selectedTree
    tree = load_tree("patrol.b3.json", tree="Patrol tree")
    tree = load_tree("huge.b3.json", max_nodes=500_000)   # raise a cap for this load
    snapshot = tree.tick()

Errors raise :class:`~cyborg.bt.problems.TreeLoadError` listing every problem; warnings are
logged (notes, which say how a value was read, at INFO). :func:`check_file` returns all
problems (errors, warnings and notes) without raising.

Every load is bounded by three caps, each a keyword here: ``max_bytes`` (bytes read, all files
together), ``max_depth`` (levels of the built tree) and ``max_nodes`` (node instances after
subtree references are expanded). Left out, each comes from its environment variable or the
default in :mod:`cyborg.bt.limits`, which explains them.
"""

from __future__ import annotations

import logging
from pathlib import Path

from cyborg.bt.blackboard import Blackboard
from cyborg.bt.builder import build
from cyborg.bt.clock import Clock
from cyborg.bt.editor_format import ProjectSpec, parse_project, read_project
from cyborg.bt.limits import Limits, size
from cyborg.bt.node import TickRecord
from cyborg.bt.problems import Problem, Severity, TreeLoadError
from cyborg.bt.registry import NodeRegistry, default_registry
from cyborg.bt.service_registry import ServiceRegistry
from cyborg.bt.service_runner import ServiceRunner
from cyborg.bt.status import Status
from cyborg.bt.tree import Tree

log = logging.getLogger("cyborg.bt")


def load_tree(source: str | Path | ProjectSpec, *, tree: str | None = None,
              registry: NodeRegistry | None = None, clock: Clock | None = None,
              blackboard: Blackboard | None = None,
              stub_missing: Status | None = None, max_bytes: int | None = None,
              max_depth: int | None = None, max_nodes: int | None = None,
              services: ServiceRegistry | None = None) -> Tree:
    """Loads a behavior3editor export (a path or a parsed project) into a runnable tree.

    ``tree`` picks a tree by id or title (default: the file's selectedTree). ``registry``
    defaults to :func:`~cyborg.bt.registry.default_registry`. ``stub_missing`` stands a stub
    returning that status in for every node without a Python class. ``max_bytes``,
    ``max_depth`` and ``max_nodes`` raise or lower the caps of :mod:`cyborg.bt.limits`
    (``max_bytes`` does not apply to a project already parsed). ``services`` defaults to
    :func:`~cyborg.bt.service_registry.default_service_registry`, read only when a composite
    declares services.
    """
    limits = _limits(source, max_bytes, max_depth, max_nodes)
    project = source if isinstance(source, ProjectSpec) else read_project(source, limits=limits)
    blackboard = blackboard if blackboard is not None else Blackboard()
    record = TickRecord()
    result = build(project, default_registry() if registry is None else registry, tree=tree,
                   blackboard=blackboard, record=record, stub_missing=stub_missing,
                   limits=limits, services=services)
    errors = [p for p in result.problems if p.is_error]
    if errors or result.root is None or result.tree is None:
        raise TreeLoadError(result.problems)
    for problem in result.problems:  # a note says how the file was read: no warning
        log.log(logging.INFO if problem.severity is Severity.NOTE else logging.WARNING, "%s",
                problem)
    return Tree(result.root, record=record, blackboard=blackboard, clock=clock,
                source=project.source, tree_id=result.tree.id, title=result.tree.title,
                services=ServiceRunner(result.services) if result.services else None)


def loads_tree(text: str, **options: object) -> Tree:
    """:func:`load_tree` for JSON text instead of a file (``max_bytes`` caps the text)."""
    caps = {key: options.get(key) for key in ("max_bytes", "max_depth", "max_nodes")}
    limits = _limits("<string>", **caps)  # type: ignore[arg-type]
    encoded = len(text.encode("utf-8", "surrogatepass"))
    if encoded > limits.max_bytes:
        raise TreeLoadError([Problem(
            f"the text holds {size(encoded)}; a load reads at most {size(limits.max_bytes)} "
            f"({limits.how_to_raise('max_bytes')})", "<string>", field="text")])
    limits.bytes_read = encoded
    return load_tree(parse_project(text, limits=limits), **options)  # type: ignore[arg-type]


def check_file(path: str | Path, *, tree: str | None = None,
               registry: NodeRegistry | None = None, services: ServiceRegistry | None = None,
               stub_missing: Status | None = None, max_bytes: int | None = None,
               max_depth: int | None = None, max_nodes: int | None = None) -> list[Problem]:
    """Every problem in a file, errors and warnings, checking *all* its trees.

    Each tree is built within the caps, as :func:`load_tree` would build it; a file that cannot
    be read or parsed gives the problems that stopped it.
    """
    try:
        limits = _limits(path, max_bytes, max_depth, max_nodes)
        project = read_project(path, limits=limits)
    except TreeLoadError as exc:
        return exc.problems
    result = build(project, default_registry() if registry is None else registry, tree=tree,
                   stub_missing=stub_missing, check_all=True, limits=limits, services=services)
    return result.problems


def _limits(source: str | Path | ProjectSpec, max_bytes: int | None, max_depth: int | None,
            max_nodes: int | None) -> Limits:
    """The caps of one load; a bad environment variable is a problem of the file loaded."""
    where = source.source if isinstance(source, ProjectSpec) else str(source)
    return Limits.resolve(max_bytes, max_depth, max_nodes, source=where)
