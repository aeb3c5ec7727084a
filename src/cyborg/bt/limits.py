"""How much a tree file may ask of the engine: the caps every load enforces.

A tree file may come from anyone who can leave a file where the robot reads it, so loading
is bounded before anything is built or ticked:

* ``max_bytes``, default 16 MiB: bytes read for one load, the tree file and every file it
  references (behavior3 v1 subtrees, imports, node definitions) together;
* ``max_depth``, default 150 levels: nesting of the built tree from the root to the deepest
  leaf, where every subtree reference counts as a level of its own;
* ``max_nodes``, default 100,000: node instances once subtree references are expanded (each use
  of a subtree builds its own copy, so ``n`` levels of doubled references make ``2**n``).

Each is a keyword of :func:`~cyborg.bt.loader.load_tree`, :func:`~cyborg.bt.loader.loads_tree`
and :func:`~cyborg.bt.loader.check_file`; left out, it is read from the environment
(``CYBORG_TREE_MAX_BYTES``, ``CYBORG_TREE_MAX_DEPTH``, ``CYBORG_TREE_MAX_NODES``: how to raise a
cap for ``cyborg bt`` and the tree runner), else from this module's constants, which a program
may also change. An error names the cap and both ways to raise it.

**Why 150 levels.** Ticking recurses: a parent's ``tick`` calls its child's ``execute``, two
Python frames per level, four when a node goes through its pre/post-tick slots (hooked, or
``tree.timing``). 150 levels
take at most :data:`FRAMES_PER_LEVEL` x 150 = 600 of Python's default recursion limit of 1,000,
leaving :data:`STACK_RESERVE` = 400 frames for the code that ticks the tree and for the leaves'
own calls. A deeper tree would load and then fail on every tick with ``RecursionError``, so it is
refused at load instead; the same bound makes every other walk over a loaded tree (halting,
building) safe. Raising ``max_depth`` past 150 therefore needs a higher recursion limit
(:func:`sys.setrecursionlimit`), and asking for it without one is a ``ValueError``.

Fixed bounds, not settable: a property value (a JSON list or object) may nest at most
:data:`MAX_VALUE_DEPTH` levels (nodes copy and compare them recursively), and an integer in a
file may have at most :data:`MAX_INT_DIGITS` digits (turning text into an ``int`` takes time
quadratic in its length, and Python refuses to print one of more than 4,300 digits).
docs/security.md ("Tree files") has the whole threat model.
"""

from __future__ import annotations

import os
import sys
from dataclasses import dataclass
from typing import Any

from cyborg.bt.problems import Problem, TreeLoadError
from cyborg.bt.status import NodeError

MAX_FILE_BYTES = 16 * 1024 * 1024
"""Default ``max_bytes``: bytes read for one load, all files together."""
MAX_DEPTH = 150
"""Default ``max_depth``: levels of the built tree (see the module docstring for why)."""
MAX_NODES = 100_000
"""Default ``max_nodes``: node instances after subtree references are expanded."""
MAX_VALUE_DEPTH = 32
"""Deepest nesting of lists and objects inside one property value."""
MAX_INT_DIGITS = 1000
"""Most digits an integer literal in a tree file may have: far below Python's limit of 4,300
for turning an int into text, so that values computed from one still print."""
MAX_VALUE_SIZE = 1 << 20
"""Most characters of a text, or items of a list or object, that a node may write to the
blackboard: a Concat of a list with itself 25 times took 2.1 GB in one tick."""


def check_value_size(what: str, value: Any) -> None:
    """Raises a NodeError naming ``what`` for a value past :data:`MAX_VALUE_SIZE`.

    ``what`` is the place written, ``"output 'result'"``; ``value`` counts as a text's
    characters, or a list's or object's items.
    """
    if isinstance(value, str | list | dict) and len(value) > MAX_VALUE_SIZE:
        kind = "characters" if isinstance(value, str) else "items"
        raise NodeError(f"{what} would hold {len(value):,} {kind}, more than the "
                        f"{MAX_VALUE_SIZE:,} a blackboard value may hold")


FRAMES_PER_LEVEL = 4
"""Python frames one tree level takes while ticking, with hooks on every node."""
STACK_RESERVE = 400
"""Frames left, at the depth cap, for the caller of ``tick`` and for the leaves' own calls."""

_ENVIRONMENT = {"max_bytes": "CYBORG_TREE_MAX_BYTES", "max_depth": "CYBORG_TREE_MAX_DEPTH",
                "max_nodes": "CYBORG_TREE_MAX_NODES"}


@dataclass
class Limits:
    """The caps of one load, and the bytes it has read so far (make a new one per load)."""

    max_bytes: int = MAX_FILE_BYTES
    max_depth: int = MAX_DEPTH
    max_nodes: int = MAX_NODES
    bytes_read: int = 0
    origin: dict[str, str] | None = None
    """Where each cap came from, for messages: ``"parameter"``, the variable's name, or
    ``"default"``."""
    entry: str = "load_tree"
    """The function whose keyword sets a cap, for messages (``"load_machine"`` for a mode
    file's load)."""

    @classmethod
    def resolve(cls, max_bytes: int | None = None, max_depth: int | None = None,
                max_nodes: int | None = None, *, source: str = "<string>") -> Limits:
        """The caps for one load, from the parameters, the environment or this module.

        Each cap is the parameter given, else its environment variable, else this module's
        constant (read now, so a program may change them).

        A variable that is not a positive whole number is a problem of the file ``source``
        (:class:`~cyborg.bt.problems.TreeLoadError`, naming the variable); a parameter that is
        not, or a ``max_depth`` the recursion limit cannot tick, is a ``ValueError``.
        """
        given = {"max_bytes": max_bytes, "max_depth": max_depth, "max_nodes": max_nodes}
        defaults = {"max_bytes": MAX_FILE_BYTES, "max_depth": MAX_DEPTH,
                    "max_nodes": MAX_NODES}
        values: dict[str, int] = {}
        origin: dict[str, str] = {}
        for name, value in given.items():
            variable = _ENVIRONMENT[name]
            if value is not None:
                if isinstance(value, bool) or not isinstance(value, int) or value < 1:
                    raise ValueError(f"{name} must be a positive whole number, not {value!r}")
                values[name], origin[name] = value, "parameter"
            elif os.environ.get(variable, "").strip():
                values[name], origin[name] = _from_environment(variable, source), variable
            else:
                values[name], origin[name] = defaults[name], "default"
        limits = cls(values["max_bytes"], values["max_depth"], values["max_nodes"],
                     origin=origin)
        needed = limits.max_depth * FRAMES_PER_LEVEL + STACK_RESERVE
        if needed > max(sys.getrecursionlimit(), 1000):
            message = (f"max_depth={limits.max_depth} needs a recursion limit of at least "
                       f"{needed} to tick safely; call sys.setrecursionlimit({needed}) first "
                       f"(it is {sys.getrecursionlimit()})")
            if origin["max_depth"] == _ENVIRONMENT["max_depth"]:
                raise TreeLoadError([Problem(f"{message}, or set {origin['max_depth']} lower",
                                             source, field=origin["max_depth"])])
            raise ValueError(message)
        return limits

    def how_to_raise(self, name: str) -> str:
        """``"raise it with load_tree(..., max_nodes=N) or CYBORG_TREE_MAX_NODES"``."""
        variable = _ENVIRONMENT[name]
        where = f" (now set by {variable})" if (self.origin or {}).get(name) == variable else ""
        return (f"raise it with {self.entry}(..., {name}=N) or the environment variable "
                f"{variable}{where}")

    @property
    def bytes_left(self) -> int:
        """Bytes this load may still read: ``max_bytes`` less ``bytes_read``, at least 0."""
        return max(self.max_bytes - self.bytes_read, 0)

    @property
    def max_nesting(self) -> int:
        """Deepest nesting of lists and objects a tree file's JSON may have.

        That is two levels per tree level (a v1 node and its ``children`` list), the deepest
        property value, and a few levels of the file's own frame.
        """
        return 2 * self.max_depth + MAX_VALUE_DEPTH + 16


def _from_environment(variable: str, source: str) -> int:
    text = os.environ[variable].strip().replace("_", "")
    if not (text.isascii() and text.isdigit()) or len(text) > 18 or int(text) < 1:
        raise TreeLoadError([Problem(f"{variable} must be a positive whole number, not "
                                     f"{os.environ[variable][:40]!r}", source, field=variable)])
    return int(text)


def nesting_exceeds(value: Any, limit: int) -> bool:
    """Whether lists and dicts in ``value`` nest more than ``limit`` levels.

    ``value`` is walked without recursion, so any depth is measured safely.
    """
    stack: list[tuple[Any, int]] = [(value, 0)]
    while stack:
        item, depth = stack.pop()
        if isinstance(item, dict):
            items: Any = item.values()
        elif isinstance(item, list):
            items = item
        else:
            continue
        if depth >= limit:
            return True
        stack.extend((child, depth + 1) for child in items)
    return False


def size(count: int) -> str:
    """``16777216`` -> ``"16,777,216 bytes (16 MiB)"``; the MiB only when whole."""
    mib = f" ({count // (1024 * 1024)} MiB)" if count % (1024 * 1024) == 0 else ""
    return f"{count:,} bytes{mib}"
