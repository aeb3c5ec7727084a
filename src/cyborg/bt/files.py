r"""Reading tree files without trusting them: no blocking, bounded size, clean text.

Every file a load reads (the tree file, and for behavior3 v1 its subtree files, imports and node
definitions) goes through :func:`read_text`, and every JSON text through :func:`decode_json`:

* Only **regular files** are read. The path is checked with :func:`os.stat` first, then opened
  with ``O_NONBLOCK`` and checked again on the open descriptor (in case it was swapped in
  between), so a FIFO, a device such as ``/dev/zero`` or a folder is refused at once instead of
  blocking the thread or reading forever.
* At most :attr:`Limits.bytes_left <cyborg.bt.limits.Limits.bytes_left>` bytes are read: the
  size is checked before reading and the read stops one byte past the cap, so a file that grows
  while it is read is refused too.
* JSON may nest at most :attr:`Limits.max_nesting <cyborg.bt.limits.Limits.max_nesting>`
  levels (enough for a tree ``max_depth`` deep in the nested v1 format, with its property
  values): checked on the text before it is parsed, so nothing later (a comparison, a ``str``,
  a copy) recurses through a value hundreds of levels deep, and the error has a line.
* JSON must be **clean text**: a lone UTF-16 surrogate (``"\ud800"`` with no partner) is not a
  character, cannot be written as UTF-8, and used to break ``cyborg bt dot`` and JSON output
  later; it is refused here with its line and column. So is an integer of more than
  :data:`~cyborg.bt.limits.MAX_INT_DIGITS` digits, before Python spends quadratic time on it.

Failures raise :class:`FileRefusedError` (reading) or :class:`~cyborg.bt.problems.TreeLoadError`
(decoding), each naming the file; callers turn them into located problems.
"""

from __future__ import annotations

import json
import os
import re
import stat
from pathlib import Path
from typing import Any

from cyborg.bt.json_text import TextLines, too_deep
from cyborg.bt.limits import MAX_INT_DIGITS, Limits, size
from cyborg.bt.problems import Problem, TreeLoadError

_CHUNK = 1 << 20
_ESCAPE = re.compile(r"\\(?:u([0-9a-fA-F]{4})|.)", re.DOTALL)
_RAW_SURROGATE = re.compile("[\ud800-\udfff]")


class FileRefusedError(Exception):
    """A file that is not read: the message says why (not a regular file, too large, ...)."""

    def __init__(self, reason: str, line: int | None = None) -> None:
        super().__init__(reason)
        self.reason = reason
        self.line = line


def read_text(path: Path, limits: Limits) -> str:
    """The UTF-8 text of ``path`` (a leading BOM dropped), charged to ``limits``' byte budget.

    Raises :class:`FileRefusedError` for a file that is missing or unreadable, not a regular file,
    larger than the bytes left, or not UTF-8 (with the line of the first bad byte).
    """
    try:
        before = os.stat(path)
    except OSError as exc:
        raise FileRefusedError(f"cannot read the file: {exc.strerror or exc}") from None
    _check_regular(before.st_mode)
    left = limits.bytes_left
    if before.st_size > left:
        raise FileRefusedError(_too_large(before.st_size, limits))
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0)
    try:
        descriptor = os.open(path, flags)
    except OSError as exc:
        raise FileRefusedError(f"cannot read the file: {exc.strerror or exc}") from None
    try:
        _check_regular(os.fstat(descriptor).st_mode)
        chunks: list[bytes] = []
        got = 0
        while got <= left:
            chunk = os.read(descriptor, min(_CHUNK, left + 1 - got))
            if not chunk:
                break
            chunks.append(chunk)
            got += len(chunk)
    except OSError as exc:
        raise FileRefusedError(f"cannot read the file: {exc.strerror or exc}") from None
    finally:
        os.close(descriptor)
    data = b"".join(chunks)
    if len(data) > left:
        raise FileRefusedError(_too_large(len(data), limits, at_least=True))
    limits.bytes_read += len(data)
    try:
        return data.decode("utf-8").removeprefix("\ufeff")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        raise FileRefusedError(f"the file is not UTF-8 text: byte {data[exc.start]:#04x} at line "
                          f"{line}", line) from None


def _check_regular(mode: int) -> None:
    if stat.S_ISREG(mode):
        return
    kind = ("a folder" if stat.S_ISDIR(mode) else "a FIFO" if stat.S_ISFIFO(mode)
            else "a device" if stat.S_ISCHR(mode) or stat.S_ISBLK(mode)
            else "a socket" if stat.S_ISSOCK(mode) else "not a file")
    raise FileRefusedError(f"not a regular file ({kind}); tree files are read only from regular "
                      "files")


def _too_large(count: int, limits: Limits, at_least: bool = False) -> str:
    already = (f", after {size(limits.bytes_read)} read from the files before it"
               if limits.bytes_read else "")
    more = "more than " if at_least else ""
    return (f"the file holds {more}{size(count)}{already}; a load reads at most "
            f"{size(limits.max_bytes)} in all ({limits.how_to_raise('max_bytes')})")


def decode_json(text: str, source: str, limits: Limits) -> Any:
    """Parses JSON ``text`` read from ``source``, refusing what it cannot trust.

    Raises :class:`TreeLoadError` with the line (and column) of malformed JSON, of nesting
    deeper than ``limits`` allow, of an integer with too many digits, or of a lone surrogate.
    """
    text = text.removeprefix("\ufeff")
    deep = too_deep(text, limits.max_nesting)
    if deep is not None:
        line, column = _position(text, deep)
        raise TreeLoadError([Problem(
            f"the JSON is nested more deeply than {limits.max_nesting} levels of lists and "
            f"objects, more than a tree of max_depth={limits.max_depth} levels needs "
            f"({limits.how_to_raise('max_depth')})", source, line, column)])
    try:
        data = json.loads(text, parse_int=_integer)
    except json.JSONDecodeError as exc:
        raise TreeLoadError([Problem(f"malformed JSON: {exc.msg}", source, exc.lineno,
                                     exc.colno)]) from None
    except RecursionError:
        raise TreeLoadError([Problem("malformed JSON: nested more deeply than the JSON reader "
                                     "allows", source, 1)]) from None
    except _TooManyDigitsError as exc:
        line, column = _position(text, text.find(exc.digits))
        raise TreeLoadError([Problem(
            f"a number with {len(exc.digits.lstrip('-')):,} digits; at most "
            f"{MAX_INT_DIGITS:,} are accepted", source, line, column)]) from None
    found = _lone_surrogate(text)
    if found is not None:
        line, column = _position(text, found[0])
        raise TreeLoadError([Problem(
            f"the text holds a lone UTF-16 surrogate ({found[1]}), which is not a character: "
            "replace it with the character meant (a pair such as \\ud83e\\udd16 is fine)",
            source, line, column)])
    return data


class _TooManyDigitsError(ValueError):
    def __init__(self, digits: str) -> None:
        super().__init__(digits[:20])
        self.digits = digits


def _integer(digits: str) -> int:
    if len(digits.lstrip("-")) > MAX_INT_DIGITS:
        raise _TooManyDigitsError(digits)
    try:
        return int(digits)
    except ValueError:  # the interpreter's own int-to-text limit is lower still
        raise _TooManyDigitsError(digits) from None


def _lone_surrogate(text: str) -> tuple[int, str] | None:
    """Offset and spelling of the first surrogate with no partner, raw or escaped."""
    raw = _RAW_SURROGATE.search(text)
    first = (raw.start(), f"U+{ord(raw.group()):04X}") if raw else None
    if "\\u" not in text:
        return first
    # Escapes are matched left to right, so "\\\\ud800" (a backslash, then text) is no escape.
    pending: re.Match[str] | None = None  # a high surrogate waiting for its low half
    for match in _ESCAPE.finditer(text):
        code = int(match.group(1), 16) if match.group(1) else -1
        if pending is not None:
            if 0xDC00 <= code <= 0xDFFF and match.start() == pending.end():
                pending = None
                continue
            break
        if 0xD800 <= code <= 0xDBFF:
            pending = match
        elif 0xDC00 <= code <= 0xDFFF:
            pending = match
            break
        if first is not None and match.start() > first[0]:
            return first
    if pending is None:
        return first
    escaped = (pending.start(), pending.group().lower())
    return escaped if first is None or escaped[0] < first[0] else first


def _position(text: str, offset: int) -> tuple[int | None, int | None]:
    if offset < 0:
        return None, None
    return TextLines(text).position(offset)
