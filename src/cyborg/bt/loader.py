"""One-call entry points: load a tree file and get a :class:`~cyborg.bt.tree.Tree` to tick.

    from cyborg.bt import load_tree

    tree = load_tree("patrol.b3.json")             # the file's selectedTree
    tree = load_tree("patrol.b3.json", tree="Patrol tree")
    snapshot = tree.tick()

Errors raise :class:`~cyborg.bt.problems.TreeLoadError` listing every problem; warnings are
logged. :func:`check_file` returns all problems (errors and warnings) without raising.
"""

from __future__ import annotations

import logging
from pathlib import Path

from cyborg.bt.blackboard import Blackboard
from cyborg.bt.builder import build
from cyborg.bt.clock import Clock
from cyborg.bt.editor_format import ProjectSpec, parse_project, read_project
from cyborg.bt.node import TickRecord
from cyborg.bt.problems import Problem, TreeLoadError
from cyborg.bt.registry import NodeRegistry, default_registry
from cyborg.bt.status import Status
from cyborg.bt.tree import Tree

log = logging.getLogger("cyborg.bt")


def load_tree(source: str | Path | ProjectSpec, *, tree: str | None = None,
              registry: NodeRegistry | None = None, clock: Clock | None = None,
              blackboard: Blackboard | None = None,
              stub_missing: Status | None = None) -> Tree:
    """Load a behavior3editor export (a path or a parsed project) into a runnable tree.

    ``tree`` picks a tree by id or title (default: the file's selectedTree). ``registry``
    defaults to :func:`~cyborg.bt.registry.default_registry`. ``stub_missing`` stands a stub
    returning that status in for every node without a Python class.
    """
    project = source if isinstance(source, ProjectSpec) else read_project(source)
    blackboard = blackboard if blackboard is not None else Blackboard()
    record = TickRecord()
    result = build(project, default_registry() if registry is None else registry, tree=tree,
                   blackboard=blackboard, record=record, stub_missing=stub_missing)
    errors = [p for p in result.problems if p.is_error]
    if errors or result.root is None or result.tree is None:
        raise TreeLoadError(result.problems)
    for problem in result.problems:
        log.warning("%s", problem)
    return Tree(result.root, record=record, blackboard=blackboard, clock=clock,
                source=project.source, tree_id=result.tree.id, title=result.tree.title)


def loads_tree(text: str, **options: object) -> Tree:
    """:func:`load_tree` for JSON text instead of a file."""
    return load_tree(parse_project(text), **options)  # type: ignore[arg-type]


def check_file(path: str | Path, *, tree: str | None = None,
               registry: NodeRegistry | None = None,
               stub_missing: Status | None = None) -> list[Problem]:
    """Every problem in a file, errors and warnings, checking *all* its trees."""
    try:
        project = read_project(path)
    except TreeLoadError as exc:
        return exc.problems
    result = build(project, default_registry() if registry is None else registry, tree=tree,
                   stub_missing=stub_missing, check_all=True)
    return result.problems
