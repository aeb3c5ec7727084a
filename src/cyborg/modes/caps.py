"""What one mode file may load, all its modes, trees and subtrees together.

The tree loader's caps (:mod:`cyborg.bt.limits`) bound one tree; a mode file names a tree per
mode, so without caps of its own it would multiply them: twenty modes naming one tree of 60,000
nodes built 1.2 million nodes (1.6 GB). One mode file is therefore one load:

* **bytes**: the mode file and every file it names (and their subtree files) are read within
  one ``max_bytes`` (:data:`cyborg.bt.limits.MAX_FILE_BYTES`, ``CYBORG_TREE_MAX_BYTES``); the
  mode file's own text may hold at most :data:`MAX_TEXT_BYTES`;
* **nodes**: the trees the modes run hold at most ``max_nodes`` node instances together
  (:data:`cyborg.bt.limits.MAX_NODES`, ``CYBORG_TREE_MAX_NODES``), counted on the files before
  anything is built (:func:`cyborg.bt.expansion.measure`); a tree several modes name is built
  once (:func:`tree_key`) and counted once;
* **modes and transitions**: at most :data:`MAX_MODES` and :data:`MAX_TRANSITIONS`, refused
  before any of them is read, at the line of the first one past the cap;
* **problems**: at most :data:`MAX_PROBLEMS` are listed, then one line says how many more.

The constants are read when a file is loaded, so a program may change them.
"""

from __future__ import annotations

from collections.abc import Iterable

from cyborg.bt.expansion import Size, measure
from cyborg.bt.limits import Limits
from cyborg.bt.problems import Problem
from cyborg.bt.specs import ProjectSpec
from cyborg.modes.spec import ModeSpec

MAX_MODES = 256
"""Most modes one mode file may declare (a robot's machine has a handful to a few dozen)."""
MAX_TRANSITIONS = 1024
"""Most ``[[transitions]]`` one mode file may declare."""
MAX_TEXT_BYTES = 1 << 20
"""Most bytes of the mode file's own text (``tomllib`` reads 1 MiB in about a second)."""
MAX_PROBLEMS = 100
"""Most problems a refused mode file lists; one more line counts the rest."""

TreeKey = tuple[int, str]
"""One tree as the modes name it: its file (the parsed project's identity) and its id."""


def tree_key(mode: ModeSpec) -> TreeKey:
    """The key under which modes running the same tree of the same file share one instance.

    Each file is read once per mode file (:func:`cyborg.modes.tree_sources.read_sources`), so
    the same project object means the same resolved file and the same content.
    """
    return id(mode.project), mode.tree


def first_past_text_cap(text: str) -> int | None:
    """The line on which ``text`` passes :data:`MAX_TEXT_BYTES` in UTF-8; None within it."""
    cap = MAX_TEXT_BYTES
    if len(text) <= cap // 4:  # no character takes more than 4 bytes
        return None
    data = text.encode("utf-8", "surrogatepass")
    if len(data) <= cap:
        return None
    return data.count(b"\n", 0, cap) + 1


def too_many(what: str, count: int, cap: int, where: str) -> str:
    """The message for a file past a count cap: ``the file declares 300 modes; ...``."""
    constant = "MAX_MODES" if what == "modes" else "MAX_TRANSITIONS"
    return (f"the file declares {count:,} {what}, more than the {cap:,} a mode file may have; "
            f"{where} is the first past it (cyborg.modes.caps.{constant})")


def node_budget(modes: Iterable[ModeSpec], limits: Limits, source: str) -> list[Problem]:
    """One problem, at the mode whose tree takes the modes past ``limits.max_nodes``; or none.

    Each different tree is counted once, with its expanded subtree references, as the
    builder would make it.
    """
    sizes: dict[int, dict[str, Size]] = {}
    counted: set[TreeKey] = set()
    total = 0
    for mode in modes:
        key = tree_key(mode)
        if key in counted:
            continue
        counted.add(key)
        found = _sizes(mode.project, limits, sizes).get(mode.tree)
        nodes = found.nodes if found is not None else 0
        before, total = total, total + nodes
        if total <= limits.max_nodes:
            continue
        over = nodes > limits.max_nodes
        made = f"more than {limits.max_nodes:,}" if over else f"{nodes:,}"
        others = ("" if over or not before else
                  f"; with the {before:,} of the trees of the modes before it, that is "
                  f"{total:,}")
        return [Problem(
            f"mode {mode.name!r}: its tree {mode.tree!r} makes {made} node instances{others}, "
            f"more than the {limits.max_nodes:,} one mode file may load in all (its modes' "
            f"trees together, each counted once however many modes run it); "
            f"{limits.how_to_raise('max_nodes')}", source, mode.line, field="tree")]
    return []


def _sizes(project: ProjectSpec, limits: Limits,
           known: dict[int, dict[str, Size]]) -> dict[str, Size]:
    """The sizes of ``project``'s trees, measured once per project."""
    found = known.get(id(project))
    if found is None:
        found = known[id(project)] = measure(project, limits.max_nodes)
    return found
