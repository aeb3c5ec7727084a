"""Problems found in a tree file, and the error that carries them.

Each :class:`Problem` names where it is — file and line, tree, node id and title, property —
so that a user can find it in the editor. Loading collects every problem before it gives up,
so one run of ``cyborg bt validate`` reports them all.
"""

from __future__ import annotations

import reprlib
from dataclasses import dataclass
from enum import StrEnum
from typing import Any


class Severity(StrEnum):
    """How bad a :class:`Problem` is: an error stops the load, a warning or a note does not.

    A warning is something that is probably wrong; a note says how the file was read where it
    could be misread (a loop count of infinity, run as "forever").
    """

    ERROR = "error"
    WARNING = "warning"
    NOTE = "note"


@dataclass(frozen=True)
class Problem:
    """One thing wrong (or suspicious) in a tree file."""

    message: str
    source: str = ""
    """The file, or ``"<string>"`` for text given directly."""
    line: int | None = None
    column: int | None = None
    tree: str | None = None
    """Title of the tree the problem is in (or its id if untitled)."""
    node_id: str | None = None
    node_title: str | None = None
    field: str | None = None
    """The property or JSON key at fault."""
    severity: Severity = Severity.ERROR

    @property
    def is_error(self) -> bool:
        """Whether the problem is an error, one that stops the load."""
        return self.severity is Severity.ERROR

    def __str__(self) -> str:
        where = self.source or "<string>"
        if self.line is not None:
            where += f":{self.line}"
            if self.column is not None:
                where += f":{self.column}"
        parts = []
        if self.tree is not None:
            parts.append(f"tree {self.tree!r}")
        if self.node_id is not None:
            title = f" {self.node_title!r}" if self.node_title else ""
            parts.append(f"node{title} (id {self.node_id})")
        context = ", ".join(parts)
        prefix = f"{where}: {self.severity.value}: "
        return printable(prefix + (f"{context}: " if context else "") + self.message)


def printable(text: str) -> str:
    r"""``text`` with any lone surrogate written as ``\udcff``, so it can be encoded as UTF-8.

    A file name with undecodable bytes holds some; printing it would raise.
    """
    if text.isascii():
        return text
    return text.encode("utf-8", "backslashreplace").decode("utf-8")


class TreeLoadError(Exception):
    """A tree file could not be loaded; :attr:`problems` lists every reason."""

    def __init__(self, problems: list[Problem]) -> None:
        self.problems = problems
        errors = [p for p in problems if p.is_error]
        shown = "\n".join(f"  {p}" for p in errors)
        count = f"{len(errors)} error{'s' if len(errors) != 1 else ''}"
        super().__init__(f"cannot load the tree ({count}):\n{shown}")


_SHORT = reprlib.Repr()
_SHORT.maxstring = _SHORT.maxother = 60
_SHORT.maxlong = 40  # digits shown of a huge whole number
_SHORT.maxlevel = 3


def shown(value: Any) -> str:
    """``repr(value)`` cut short for a message.

    A value from a file may be megabytes long or nested hundreds of levels deep (a plain
    ``repr`` would then exhaust the stack).
    """
    try:
        return _SHORT.repr(value)
    except ValueError:  # an int past Python's int-to-text limit
        return f"<a whole number of about {int(value.bit_length() * 0.30103):,} digits>"
