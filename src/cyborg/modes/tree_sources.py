"""The behavior3editor files a mode file names, and how a mode's ``tree`` is found in them.

A mode file names either one ``project`` or a list of ``files``, relative to its own folder.
Each is read as :func:`cyborg.bt.read_project` reads any tree file, so both editor generations
work: a behavior3editor 0.3.0 project (several trees in one file, the usual case), a 0.3.0
single-tree export, or a behavior3editor 1.x tree file (one tree per file, its subtrees in files
of their own).

A mode's ``tree`` is found, in this order:

1. a file of ``files`` given as written (``"trees/patrol.json"``) or by its name without
   suffixes (``"patrol"``): that file's selected tree (for a 1.x file, its one tree);
2. a tree whose id or title is the name, in any of the files. Two trees of that name in
   different files (or two with one title) are ambiguous: name the tree by its id.

Every file is read once per mode file, within the load's one :class:`~cyborg.bt.limits.Limits`
(the mode file's, so that all the files together stay within ``max_bytes``): two spellings of
one file (``"a.json"``, ``"./a.json"``) give the same :class:`ProjectSpec`, and modes naming one
of its trees share one instance of it (:func:`cyborg.modes.caps.tree_key`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from cyborg.bt.editor_format import ProjectSpec, read_project
from cyborg.bt.limits import Limits
from cyborg.bt.problems import Problem, TreeLoadError
from cyborg.bt.specs import choose_tree


@dataclass(frozen=True)
class TreeSource:
    """One file the mode file names: as written there, and what was read from it."""

    written: str
    path: Path
    project: ProjectSpec


def read_sources(folder: Path, written: list[str], limits: Limits | None = None
                 ) -> tuple[list[TreeSource], dict[str, list[Problem]]]:
    """Reads every file (relative to ``folder``); the problems of each that fails to load.

    All are read within ``limits`` (default: one :meth:`Limits.resolve
    <cyborg.bt.limits.Limits.resolve>` for them all); a file named twice is read once.
    """
    limits = limits if limits is not None else Limits.resolve(source=str(folder))
    sources: list[TreeSource] = []
    failed: dict[str, list[Problem]] = {}
    read: dict[Path, ProjectSpec] = {}
    for name in written:
        path = folder / name
        resolved = _resolved(path)
        project = read.get(resolved)
        if project is None:
            try:
                project = read[resolved] = read_project(path, limits=limits)
            except TreeLoadError as exc:
                failed[name] = exc.problems
                continue
        sources.append(TreeSource(name, path, project))
    return sources, failed


def find_tree(sources: list[TreeSource], name: str) -> tuple[ProjectSpec, str] | str:
    """The file and tree id that ``name`` means, or why there is none (listing what exists)."""
    for source in sources:
        if name in (source.written, _bare(source.path)):
            chosen, reason = choose_tree(source.project, None)
            if chosen is None:
                return f"{source.written}: {reason}"
            return source.project, chosen.id
    by_id = [(s, t) for s in _distinct(sources) for t in s.project.trees if t.id == name]
    found = by_id or [(s, t) for s in _distinct(sources) for t in s.project.trees
                      if t.title == name]
    if len(found) == 1:
        return found[0][0].project, found[0][1].id
    if found:
        places = ", ".join(f"{t.id!r} in {s.written}" for s, t in found)
        return f"several trees are named {name!r} ({places}); name one by its id"
    return f"no tree has the id or title {name!r}; {listing(sources)}"


def listing(sources: list[TreeSource]) -> str:
    """``trees: 'Patrol' (id p1) in mission.b3.json, ...``: what a mode may name."""
    trees = [f"{t.title!r} (id {t.id}) in {s.written}" for s in _distinct(sources)
             for t in s.project.trees]
    return "trees: " + (", ".join(trees) if trees else "none")


def _bare(path: Path) -> str:
    """``"patrol"`` for ``trees/patrol.b3.json``."""
    return path.name.split(".", 1)[0]


def _distinct(sources: list[TreeSource]) -> list[TreeSource]:
    """``sources`` with each file once (the first spelling of it)."""
    seen: set[int] = set()
    distinct: list[TreeSource] = []
    for source in sources:
        if id(source.project) not in seen:
            seen.add(id(source.project))
            distinct.append(source)
    return distinct


def _resolved(path: Path) -> Path:
    """The file ``path`` names, links followed; the path as given if it cannot be resolved."""
    try:
        return path.resolve()
    except (OSError, RuntimeError, ValueError):
        return path
