r"""The small print of ARNL map lines: fields, quotes, numbers and their bounds.

A map line is split into fields as ARIA's ``ArArgumentBuilder`` splits it (with quotes
"pre-compressed", as ``ArMap`` asks):

* fields are separated by ASCII whitespace (space, tab, vertical tab, form feed, carriage
  return: C's ``isspace``); nothing else separates them, not U+0085 nor U+00A0;
* a field that *starts* with ``"`` runs to the first ``"`` that is followed by whitespace or
  ends the line, so it may hold spaces and even quotes (``"the 5"-wide door"``); the outer
  quotes are dropped, backslashes are kept as they are (``"C:\maps\"``);
* any other field ends at whitespace, quotes and all (``Name=Goal``).

:func:`split_fields` does this in one pass with compiled patterns, in time linear in the
line's length; ``shlex``, used before, took minutes for a 5 MB description.

Every number that places something is checked here before it is used: a coordinate
(millimetres) or heading (degrees) must be a finite number within ±:data:`MAX_COORDINATE_MM`
(10 km; ARNL maps a building). NaN or 1e300 used to load and then crash the planner; 1e9 mm
asked the grid for gigabytes. Header summaries (``MinPos``, ``NumPoints``, ``Resolution``,
``OriginLatLongAlt`` ...) are informational (the reader recomputes them from the data) but must
still be numbers of the right kind, so garbage is named where it is rather than carried along.
"""

from __future__ import annotations

import re

MAX_COORDINATE_MM = 1e7
"""Largest magnitude of a coordinate (mm) or heading (degrees) in a map: 10 km from the origin."""

_INT32 = 2.0**31  # ARIA writes ±2147483647 into MinPos/MaxPos of an empty scan

_BLANKS = re.compile(r"[ \t\v\f\r]*")
_BARE = re.compile(r"[^ \t\v\f\r]*")
_CLOSING = re.compile(r'"(?=[ \t\v\f\r]|\Z)')


class MapError(ValueError):
    """A map file that cannot be read; the message names the file and the line."""

    def __init__(self, source: str, line: int, message: str) -> None:
        super().__init__(f"{source}:{line}: {message}" if line else f"{source}: {message}")
        self.source, self.line, self.reason = source, line, message


def split_fields(text: str) -> list[str]:
    """The fields of one line's values, split by ARIA's rules (see the module's docstring).

    ValueError if a quoted field is never closed.
    """
    fields: list[str] = []
    position, end = 0, len(text)
    while True:
        blanks = _BLANKS.match(text, position)
        assert blanks is not None  # the pattern matches the empty string too
        position = blanks.end()
        if position >= end:
            return fields
        if text[position] == '"':
            closing = _CLOSING.search(text, position + 1)
            if closing is None:
                raise ValueError(f"the quoted field at column {position + 1} is never closed "
                                 "(a quote ends a field only before a space or the line's end)")
            fields.append(text[position + 1:closing.start()])
            position = closing.end()
        else:
            bare = _BARE.match(text, position)
            assert bare is not None  # the pattern matches the empty string too
            fields.append(bare.group())
            position = bare.end()


def shown(token: str, limit: int = 30) -> str:
    """``token`` quoted for an error message, cut to ``limit`` characters."""
    return repr(token if len(token) <= limit else token[:limit] + "…")


def coordinate(token: str, what: str, field: str, source: str, line: int,
               unit: str = "millimetres") -> float:
    """``token`` as a number within ±MAX_COORDINATE_MM.

    Raises MapError naming ``what`` and ``field`` (e.g. ``Cairn Goal 'el5'`` and ``x``)
    otherwise; ``unit`` is ``"degrees"`` for headings.
    """
    try:
        value = float(token)
    except ValueError:
        raise MapError(source, line, f"{what}: a coordinate is not a number: {field} is "
                                     f"{shown(token)}") from None
    if not abs(value) <= MAX_COORDINATE_MM:  # also false for NaN
        raise MapError(source, line, out_of_bounds(what, field, token, unit))
    return value


def out_of_bounds(what: str, field: str, token: str, unit: str = "millimetres") -> str:
    """The message for a coordinate that is not finite or lies too far out."""
    kind = "heading" if unit == "degrees" else "coordinate"
    return (f"{what}: {field} is {shown(token)}; every {kind} must be a finite number of "
            f"{unit} within ±{MAX_COORDINATE_MM:.0f} (10 km)")


# ---------------------------------------------------------------------- header summaries
def _numbers_within(tokens: list[str], low: float, high: float, whole: bool) -> bool:
    try:
        values = [float(token) for token in tokens]
    except ValueError:
        return False
    return all(low <= value <= high and (not whole or value == int(value)) for value in values)


def check_header(key: str, tokens: list[str], source: str, line: int) -> None:
    """MapError unless the values of a known numeric header key are numbers of its kind.

    Keys may carry a sensor's prefix in 2D-Map-Ex files (``Laser2MinPos``). A key without
    values is left alone; unknown keys are kept verbatim by the reader and not checked.
    """
    if not tokens:
        return
    found = shown(" ".join(tokens), 60)
    if key.endswith(("MinPos", "MaxPos")):
        if len(tokens) != 2 or not _numbers_within(tokens, -_INT32, _INT32, whole=False):
            raise MapError(source, line, f"{key}: expected x and y, two finite numbers of "
                                         f"millimetres within ±{_INT32:.0f}, found {found}")
    elif key.endswith(("NumPoints", "NumLines")):
        if len(tokens) != 1 or not _numbers_within(tokens, 0, _INT32, whole=True):
            raise MapError(source, line, f"{key}: expected a whole number from 0 to "
                                         f"{_INT32:.0f}, found {found}")
    elif key.endswith("Resolution"):
        if len(tokens) != 1 or not _numbers_within(tokens, 0, MAX_COORDINATE_MM, whole=False):
            raise MapError(source, line, f"{key}: expected a finite number of millimetres "
                                         f"from 0 to {MAX_COORDINATE_MM:.0f}, found {found}")
    elif key in ("OriginLatLongAlt", "OriginLatLonAlt"):
        ok = len(tokens) == 3 and all(
            _numbers_within([token], -limit, limit, whole=False)
            for token, limit in zip(tokens, (90.0, 180.0, MAX_COORDINATE_MM), strict=True))
        if not ok:
            raise MapError(source, line, f"{key}: expected latitude (±90°), longitude (±180°) "
                                         f"and altitude (m), found {found}")

