r"""Facts about JSON *text* that a parsed value no longer has: lines, and how deep it nests.

Tree files are JSON; a problem found in the parsed data must still name the line it came
from, and nesting must be measured before ``json.loads`` recurses into it. Both readers of tree
files (behavior3editor 0.3.0 and 1.x) and the web monitor's message check use these helpers:

    lines = TextLines(text)
    lines.line_of(text.find('"id"'))               # 1-based line of an offset
    lines.position(offset)                         # (line, column), both 1-based
    first_lines(text, r'"id"\s*:\s*"([^"]*)"')     # {value: line of its first occurrence}
    too_deep(text, 32)                             # offset of the 33rd open bracket, or None

Brackets inside strings never count, and every scan is linear in the text's length.
"""

from __future__ import annotations

import bisect
import itertools
import re

_NOT_BRACKET = re.compile(r"[^\[\]{}]+")
_BRACKET_OR_STRING = re.compile(r'"(?:[^"\\]|\\.)*(?:"|\\?\Z)|[\[\]{}]')  # a string may run
# to the end (malformed, but then it ends the scan: no quadratic retries from later quotes)
_STEP = {"[": 1, "{": 1, "]": -1, "}": -1}


class TextLines:
    """Where each line of a text starts, to turn character offsets into lines and columns."""

    def __init__(self, text: str) -> None:
        self._starts = [0] + [match.end() for match in re.finditer("\n", text)]

    def line_of(self, offset: int) -> int:
        """The 1-based line holding the character at ``offset``."""
        return bisect.bisect_right(self._starts, offset)

    def position(self, offset: int) -> tuple[int, int]:
        """The 1-based line and column of the character at ``offset``."""
        line = self.line_of(offset)
        return line, offset - self._starts[line - 1] + 1


def first_lines(text: str, pattern: str | re.Pattern[str],
                lines: TextLines | None = None) -> dict[str, int]:
    """For each value ``pattern`` captures in ``text``, the line where it first occurs.

    Later occurrences keep the first line. The value is the match's group that matched (a
    pattern may offer alternatives, such as a quoted or a numeric id, each in a group of its
    own). ``lines`` saves indexing the text again.
    """
    lines = lines if lines is not None else TextLines(text)
    found: dict[str, int] = {}
    for match in re.finditer(pattern, text):
        found.setdefault(match.group(match.lastindex or 0), lines.line_of(match.start()))
    return found


def too_deep(text: str, cap: int) -> int | None:
    """Offset of the first bracket opening nesting level ``cap + 1``; None when there is none.

    Brackets in strings do not count. Quick in the common case: when no bracket, inside a
    string or not, could reach that depth, the answer comes from counting brackets alone.
    """
    brackets = _NOT_BRACKET.sub("", text)
    if len(brackets) <= cap or max(itertools.accumulate(map(_STEP.__getitem__, brackets)),
                                   default=0) <= cap:
        return None
    depth = 0
    for match in _BRACKET_OR_STRING.finditer(text):
        token = match.group()
        if token in "[{":
            depth += 1
            if depth > cap:
                return match.start()
        elif token in "]}":
            depth -= 1
    return None
