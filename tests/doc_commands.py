"""The shell commands that README.md and docs/*.md tell a reader to run, as written.

A command is a line of a fenced code block, or a span of inline code, that starts with one of
the given programs (``cyborg``, ``python3``); a line ending in a backslash goes on on the next
one, and a comment (`` # ...``) is left out. Each comes with the file and line it is written on,
so that a failing check names where to mend it.
"""

from __future__ import annotations

import re
import shlex
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DOCUMENTS = (ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md")))
INLINE = re.compile(r"(?<!`)`([^`\n]+)`(?!`)")
FENCE = "```"


@dataclass(frozen=True)
class DocCommand:
    """One command as a document writes it."""

    path: Path
    line: int
    text: str
    fenced: bool
    """Whether it is a line of a fenced code block (a command to paste), or inline code (which
    may name a command without its arguments)."""

    @property
    def where(self) -> str:
        """``README.md:12``: the file, from the repository root, and the line."""
        return f"{self.path.relative_to(ROOT)}:{self.line}"

    @property
    def words(self) -> list[str]:
        """The command's words as the shell splits them (quotes removed)."""
        return shlex.split(self.text)


def _without_comment(line: str) -> str:
    """The line up to a shell comment: a ``#`` that starts a word, outside quotes."""
    quote = ""
    for index, char in enumerate(line):
        if quote:
            quote = "" if char == quote else quote
        elif char in "'\"":
            quote = char
        elif char == "#" and (index == 0 or line[index - 1].isspace()):
            return line[:index].rstrip()
    return line.rstrip()


def _code_lines(path: Path) -> Iterator[tuple[int, str, bool]]:
    """(line number, text, fenced) of each line of a fenced block, continued lines joined, and
    of each span of inline code outside the blocks."""
    lines = path.read_text(encoding="utf-8").splitlines()
    in_block = False
    pending: tuple[int, str] | None = None
    prose: tuple[int, str] | None = None  # a line whose inline code goes on on the next
    for number, line in enumerate(lines, start=1):
        if line.lstrip().startswith(FENCE):
            in_block = not in_block
            continue
        if not in_block:
            if prose is not None:
                number, line = prose[0], f"{prose[1]} {line.strip()}"
                prose = None
            if line.count("`") % 2 and line.strip():
                prose = (number, line)
                continue
            for span in INLINE.findall(line):
                yield number, span, False
            continue
        text = _without_comment(line).strip()
        if pending is not None:
            number, text = pending[0], f"{pending[1]} {text}"
            pending = None
        if text.endswith("\\"):
            pending = (number, text[:-1].rstrip())
            continue
        yield number, text, True


def doc_commands(*programs: str,
                 documents: tuple[Path, ...] = DOCUMENTS) -> list[DocCommand]:
    """Every command of the documents that starts with one of ``programs``."""
    found = []
    for path in documents:
        for number, text, fenced in _code_lines(path):
            text = text.removeprefix("$ ").strip()
            if text.split(" ", 1)[0] in programs:
                found.append(DocCommand(path, number, text, fenced))
    return found
