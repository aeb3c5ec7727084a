"""Where a table or key stands in TOML text, so that an error can name its line.

Python's :mod:`tomllib` returns plain dicts and lists without positions. :class:`TomlLines`
scans the text once, line by line, and remembers the first line of every table header and key
by its path: ``("modes", "normal")`` for ``[modes.normal]``, ``("transitions", 2, "when")`` for
the ``when`` key in the third ``[[transitions]]`` table, ``("initial",)`` for a top-level key.
Dotted keys (``modes.demo.tree = "demo"``) and quoted keys (``[modes."low power"]``) are
understood; keys inside an inline table or a multi-line array are found by the line of the key
that holds them. Text inside strings (one-line, multi-line, literal) is never mistaken for a
header or a key.

:meth:`TomlLines.line` finds the nearest known line for a path: the key's own line, else the
line of the table around it, so a message always points close to the fault.
"""

from __future__ import annotations

import re

Path = tuple[str | int, ...]
"""A place in the document: table and key names, and the index within an array of tables."""

_BARE = re.compile(r"[A-Za-z0-9_-]+")


class TomlLines:
    """Line numbers (from 1) of the headers and keys of one TOML text."""

    def __init__(self, text: str) -> None:
        self._lines: dict[Path, int] = {}
        self._counts: dict[tuple[str, ...], int] = {}
        self._scan(text)

    def line(self, *path: str | int) -> int | None:
        """The line of ``path``, or of the nearest table or key above it; None if none."""
        while path:
            found = self._lines.get(path)
            if found is not None:
                return found
            path = path[:-1]
        return None

    # ------------------------------------------------------------------ scanning
    def _scan(self, text: str) -> None:
        table: Path = ()
        depth = 0  # open brackets and braces of a value that goes on over several lines
        quote = ""  # the delimiter of a multi-line string left open
        for number, raw in enumerate(text.splitlines(), start=1):
            line = raw
            if quote:
                end = line.find(quote)
                if end < 0:
                    continue
                line, quote = line[end + 3:], ""
                if depth == 0:
                    continue  # what follows a closed string on its last line is no key
            if depth:
                depth, quote = _value_depth(line, depth)
                continue
            stripped = line.strip()
            if not stripped or stripped.startswith("#"):
                continue
            if stripped.startswith("["):
                table = self._header(stripped, number) or table
                continue
            key, rest = _split_key(stripped)
            if key is None:
                continue
            self._remember((*table, *key), number)
            depth, quote = _value_depth(rest, 0)

    def _header(self, text: str, number: int) -> Path | None:
        array = text.startswith("[[")
        inner = text[2:] if array else text[1:]
        keys, rest = _keys(inner)
        if not keys or not rest.startswith("]]" if array else "]"):
            return None
        names = tuple(keys)
        if not array:
            self._remember(names, number)
            return names
        index = self._counts.get(names, 0)
        self._counts[names] = index + 1
        path: Path = (*names, index)
        self._remember(path, number)
        self._lines.setdefault(names, number)
        return path

    def _remember(self, path: Path, number: int) -> None:
        self._lines.setdefault(path, number)


def _keys(text: str) -> tuple[list[str], str]:
    """The dotted key at the start of ``text`` and what follows it; no keys if malformed."""
    keys: list[str] = []
    position = 0
    while True:
        while position < len(text) and text[position] in " \t":
            position += 1
        if position < len(text) and text[position] in "\"'":
            closing = text[position]
            end = position + 1
            chars: list[str] = []
            while end < len(text) and text[end] != closing:
                if closing == '"' and text[end] == "\\" and end + 1 < len(text):
                    end += 1
                chars.append(text[end])
                end += 1
            if end >= len(text):
                return [], ""
            keys.append("".join(chars))
            position = end + 1
        else:
            match = _BARE.match(text, position)
            if match is None:
                return [], ""
            keys.append(match.group())
            position = match.end()
        while position < len(text) and text[position] in " \t":
            position += 1
        if position < len(text) and text[position] == ".":
            position += 1
            continue
        return keys, text[position:]


def _split_key(text: str) -> tuple[tuple[str, ...] | None, str]:
    keys, rest = _keys(text)
    if not keys or not rest.startswith("="):
        return None, ""
    return tuple(keys), rest[1:]


def _value_depth(text: str, depth: int) -> tuple[int, str]:
    """Brackets still open after ``text``, and the multi-line string delimiter left open."""
    position = 0
    while position < len(text):
        char = text[position]
        if char == "#":
            break
        if text.startswith(('"""', "'''"), position):
            delimiter = text[position:position + 3]
            end = text.find(delimiter, position + 3)
            if end < 0:
                return depth, delimiter
            position = end + 3
            continue
        if char in "\"'":
            position += 1
            while position < len(text) and text[position] != char:
                position += 2 if char == '"' and text[position] == "\\" else 1
        elif char in "[{":
            depth += 1
        elif char in "]}":
            depth = max(0, depth - 1)
        position += 1
    return depth, ""
