"""Bounds a mode file's TOML text must keep before :mod:`tomllib` reads it.

``tomllib`` reads nested arrays and inline tables by recursion, so a file of 1,000 nested
``[`` raised ``RecursionError``; and it reads a whole number of over 4,300 digits into a
``ValueError`` that names no line. One linear pass over the text, outside strings and comments,
finds the first bracket nested deeper than :data:`MAX_NESTING` and the first run of digits longer
than :data:`MAX_DIGITS`, with its line and column::

    first_too_deep("x = [[[1]]]", cap=2)    # -> (1, 7): the third "["
    first_long_number("x = 1" + "0" * 200)  # -> (1, 5)
"""

from __future__ import annotations

import re

MAX_NESTING = 32
"""Deepest nesting of arrays and inline tables a mode file may have (it needs two or three)."""
MAX_DIGITS = 100
"""Longest run of digits a number in a mode file may have (no setting needs more than 20)."""

_TOKEN = re.compile(r'''
    (?P<string>"""(?:[^"\\]++|\\.|""?(?!"))*+(?:"""|$)
              |'\'\''(?:[^']++|''?(?!'))*+(?:'\'\''|$)
              |"(?:[^"\\\n]++|\\.)*+(?:"|$)
              |'[^'\n]*+(?:'|$))
  | (?P<comment>\#[^\n]*)
  | (?P<open>[\[{])
  | (?P<close>[\]}])
  | (?P<digits>[0-9][0-9_]*)
  | (?P<other>[^"'#\[\]{}0-9]+)
''', re.VERBOSE | re.DOTALL)


def _place(text: str, offset: int) -> tuple[int, int]:
    line = text.count("\n", 0, offset) + 1
    return line, offset - (text.rfind("\n", 0, offset) + 1) + 1


def first_too_deep(text: str, cap: int = MAX_NESTING) -> tuple[int, int] | None:
    """Line and column of the first ``[`` or ``{`` nested deeper than ``cap``; None if none."""
    depth = 0
    for match in _TOKEN.finditer(text):
        kind = match.lastgroup
        if kind == "open":
            depth += 1
            if depth > cap:
                return _place(text, match.start())
        elif kind == "close":
            depth = max(depth - 1, 0)
    return None


def first_long_number(text: str, digits: int = MAX_DIGITS) -> tuple[int, int] | None:
    """Line and column of the first run of more than ``digits`` digits outside strings."""
    for match in _TOKEN.finditer(text):
        if match.lastgroup == "digits" and len(match.group()) > digits:
            return _place(text, match.start())
    return None
