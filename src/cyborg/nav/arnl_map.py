"""Reading ARNL ``.map`` files (the "2D-Map" format of MobileRobots' ARIA, ARNL and MobileSim).

A map file is text, one record per line::

    2D-Map
    MinPos: -41360 -88140                      header keys, kept verbatim
    MapInfo: GoalType "Name=Goal" ...          declared object types
    Cairn: GoalWithHeading -33768 -32545 12.5 "The lecture hall." ICON "el5"
    Cairn: ForbiddenArea 0 0 90.000000 "" ICON "" -67552 5362 -55700 13464
    LINES                                      vector walls: x1 y1 x2 y2
    -39981 -90275 -35580 -90278
    DATA                                       laser-scanned points: x y
    -41360 1460

Files store millimetres and degrees; :func:`read_map` converts to metres and radians, so nothing
beyond this module ever sees a millimetre. Errors are :class:`MapError` naming file and line.

A map may come from anyone (the ``load_map_file`` service takes a path from any client), so
reading it is bounded: fields are split in linear time by ARIA's quoting rules, every
coordinate and heading must be finite and within 10 km (:mod:`cyborg.nav.map_syntax`), and the
file's size, the grid it needs and its number of objects are capped (:mod:`cyborg.nav.map_limits`,
with the environment variables that raise each cap).

The format is ASCII, but names and descriptions are free text, and the tools that write maps
disagree on how to store "ø": ARIA copies bytes, Windows editors write the ANSI code page
(Windows-1252, a superset of Latin-1), newer editors UTF-8, some with a byte-order mark.
:func:`decode_map_bytes` reads all of these without mojibake (see there).

Map objects (cairns) are :class:`MapObject`; see :mod:`cyborg.nav.map_objects` for what each
kind means (goals, docks, forbidden lines and areas, simulator boxes).
"""

from __future__ import annotations

import codecs
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from cyborg.nav.map_limits import MapLimits, check_grid, map_limits, read_capped
from cyborg.nav.map_objects import MapObject, MapType, declared_categories
from cyborg.nav.map_syntax import (
    MAX_COORDINATE_MM,
    MapError,
    check_header,
    coordinate,
    out_of_bounds,
    split_fields,
)

__all__ = ["MAP_INTROS", "ArnlMap", "MapError", "MapType", "decode_map_bytes", "parse_map",
           "read_map", "split_fields"]

MAP_INTROS = ("2D-Map", "2D-Map-Ex", "2D-Map-Ex2", "2D-Map-Ex3", "2D-Map-Ex4")


@dataclass
class ArnlMap:
    """One map: header, declared types, objects, walls (``lines``) and scanned ``points``.

    ``lines`` is an (N, 4) array of ``x1 y1 x2 y2`` and ``points`` an (M, 2) array, both in
    metres in the map frame. Sensor sections of 2D-Map-Ex files (``<Sensor>_LINES``,
    ``<Sensor>_DATA``) are in ``sensor_lines`` and ``sensor_points``; header keys the reader does
    not interpret are kept, in order, in ``header``.
    """

    source: str
    intro: str
    header: dict[str, list[str]] = field(default_factory=dict)
    types: list[MapType] = field(default_factory=list)
    objects: list[MapObject] = field(default_factory=list)
    lines: np.ndarray = field(default_factory=lambda: np.zeros((0, 4)))
    points: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    sensor_lines: dict[str, np.ndarray] = field(default_factory=dict)
    sensor_points: dict[str, np.ndarray] = field(default_factory=dict)

    # ------------------------------------------------------------------ objects by kind
    def goals(self) -> list[MapObject]:
        """Goals and docks, in file order: everything a robot can be sent to by name."""
        return [item for item in self.objects if item.is_goal or item.is_dock]

    def docks(self) -> list[MapObject]:
        """The docks, in file order."""
        return [item for item in self.objects if item.is_dock]

    def goal(self, name: str) -> MapObject:
        """The goal or dock called ``name``; KeyError listing the names otherwise."""
        for item in self.goals():
            if item.name == name:
                return item
        known = ", ".join(repr(item.name) for item in self.goals()) or "none"
        raise KeyError(f"{self.source}: no goal named {name!r} (goals: {known})")

    def homes(self) -> list[MapObject]:
        """The ``RobotHome`` points and areas, in file order: where a robot may start."""
        return [item for item in self.objects if item.kind == "RobotHome"]

    def forbidden_lines(self) -> list[MapObject]:
        """The lines the robot must not cross, in file order."""
        return [item for item in self.objects if item.is_forbidden_line]

    def forbidden_areas(self) -> list[MapObject]:
        """The areas the robot must not enter, in file order."""
        return [item for item in self.objects if item.is_forbidden_area]

    def sim_obstacles(self) -> list[MapObject]:
        """Boxes that only the simulator puts into the world (``Sim.BoxObstacle`` sectors)."""
        return [item for item in self.objects if item.is_sim_obstacle]

    # ------------------------------------------------------------------ extent
    def bounds(self) -> tuple[float, float, float, float]:
        """``(min_x, min_y, max_x, max_y)`` over walls, points and objects, in metres."""
        xs: list[np.ndarray] = [self.points[:, 0], self.lines[:, 0], self.lines[:, 2]]
        ys: list[np.ndarray] = [self.points[:, 1], self.lines[:, 1], self.lines[:, 3]]
        for item in self.objects:
            corners = item.corners()
            if corners is not None:
                xs.append(corners[:, 0])
                ys.append(corners[:, 1])
            xs.append(np.array([item.x]))
            ys.append(np.array([item.y]))
        all_x, all_y = np.concatenate(xs), np.concatenate(ys)
        if all_x.size == 0:
            return (0.0, 0.0, 0.0, 0.0)
        return (float(all_x.min()), float(all_y.min()), float(all_x.max()), float(all_y.max()))


# ---------------------------------------------------------------------- reading
def read_map(path: str | Path, limits: MapLimits | None = None) -> ArnlMap:
    """Read an ARNL map file.

    Raises :class:`MapError` (naming file and line) if it is not one, or if it exceeds a cap of
    ``limits`` (default: :func:`~cyborg.nav.map_limits.map_limits`).
    """
    limits = limits or map_limits()
    raw = read_capped(path, limits.max_bytes)
    try:
        text = decode_map_bytes(raw)
    except UnicodeDecodeError as exc:
        raise MapError(str(path), 0, f"starts with a UTF-16 byte-order mark but is not UTF-16 "
                                     f"({exc.reason} at byte {exc.start})") from exc
    return parse_map(text, str(path), limits)


def decode_map_bytes(raw: bytes) -> str:
    """The text of a map file, whichever way its non-ASCII characters were written.

    * A UTF-8 byte-order mark is dropped (it is not part of ``2D-Map``).
    * A file that is valid UTF-8 is read as UTF-8. Latin-1 text is practically never valid
      UTF-8 (every accented letter would need the right continuation bytes after it), while
      UTF-8 read as Latin-1 turns "ø" (bytes C3 B8) into "Ã" and a cedilla.
    * Otherwise each line on its own is UTF-8 if it can be, else Windows-1252 (Latin-1 plus
      printable characters, such as "…" and "€", where Latin-1 has invisible control codes),
      else Latin-1 (for the five bytes Windows-1252 leaves undefined). Line by line, because a
      file edited by two tools may hold both.
    * A UTF-16 file (a byte-order mark ``FF FE`` or ``FE FF``, as Notepad's "Unicode" writes)
      is decoded as such; UnicodeDecodeError if it is broken.
    """
    if raw.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)):
        return raw.decode("utf-16")
    raw = raw.removeprefix(codecs.BOM_UTF8)
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError:
        return "\n".join(_decode_line(line) for line in raw.split(b"\n"))


def _decode_line(line: bytes) -> str:
    for encoding in ("utf-8", "cp1252"):
        try:
            return line.decode(encoding)
        except UnicodeDecodeError:
            pass
    return line.decode("latin-1")  # never fails: every byte is a character


def parse_map(text: str, source: str = "<map>", limits: MapLimits | None = None) -> ArnlMap:
    """Parse the text of a map file; ``source`` names it in error messages.

    Lines end at LF, CR LF or CR, and nowhere else: ``str.splitlines`` would also break at
    characters such as U+0085 or U+2028 inside a name, and shift every later line number.
    The map is checked against ``limits`` (objects while reading; the grid it needs at 5 cm
    at the end), so a map that loads can be planned on and simulated.
    """
    limits = limits or map_limits()
    text = text.removeprefix("\ufeff")
    rows = text.replace("\r\n", "\n").replace("\r", "\n").split("\n")
    first = next((index for index, row in enumerate(rows) if row.strip()), None)
    if first is None:
        raise MapError(source, 0, "empty file, expected a '2D-Map' line")
    intro = rows[first].strip()
    if intro not in MAP_INTROS:
        raise MapError(source, first + 1, f"expected '2D-Map' (an ARNL map), found {intro[:40]!r}")
    result = ArnlMap(source=source, intro=intro)
    section: str | None = None  # e.g. "LINES", "DATA", "Laser2_LINES"
    section_rows: list[str] = []
    section_lines: list[int] = []
    counts = {"Cairn": 0, "MapInfo": 0, "header": 0}
    for index in range(first + 1, len(rows)):
        row = rows[index].strip()
        if not row:
            continue
        if row == "LINES" or row == "DATA" or row.endswith(("_LINES", "_DATA")):
            _store_section(result, section, section_rows, section_lines, source)
            section, section_rows, section_lines = row, [], []
            continue
        if section is not None and (row[0].isdigit() or row[0] in "-+."):
            section_rows.append(row)
            section_lines.append(index + 1)
            continue
        if section is not None:
            _store_section(result, section, section_rows, section_lines, source)
            section, section_rows, section_lines = None, [], []
        _header_line(result, row, index + 1, source, limits, counts)
    _store_section(result, section, section_rows, section_lines, source)
    declared = declared_categories(result.types)
    result.objects = [item.classified(declared) for item in result.objects]
    for item in result.objects:
        if (item.is_forbidden_line or item.is_forbidden_area) and item.region is None:
            raise MapError(source, item.line or 0, f"Cairn {item.kind} {item.name!r}: a "
                           "forbidden zone needs its region (from x, from y, to x, to y after "
                           "the name)")
    check_grid(result, limits=limits)
    return result


def _header_line(result: ArnlMap, row: str, line: int, source: str, limits: MapLimits,
                 counts: dict[str, int]) -> None:
    """Take in one ``Key: values`` line.

    ``counts`` (Cairn, MapInfo, other header lines so far) are held to the cap on objects.
    """
    key, colon, rest = row.partition(":")
    if not colon or not key or " " in key:
        raise MapError(source, line, f"expected 'Key: values', LINES or DATA, found {row[:60]!r}")
    kind = key if key in ("Cairn", "MapInfo") else "header"
    counts[kind] += 1
    if counts[kind] > limits.max_objects:
        raise MapError(source, line, f"more than {limits.max_objects:,} "
                                     f"{'other header' if kind == 'header' else kind} lines, the "
                                     "cap for a map; set CYBORG_MAP_MAX_OBJECTS to raise it")
    try:
        tokens = split_fields(rest)
    except ValueError as exc:
        raise MapError(source, line, f"{key}: {exc}") from None
    if key == "Cairn":
        result.objects.append(_cairn(tokens, line, source))
    elif key == "MapInfo":
        if not tokens:
            raise MapError(source, line, "MapInfo without a category")
        settings = dict(token.partition("=")[::2] for token in tokens[1:])
        result.types.append(MapType(tokens[0], settings, line))
    else:
        check_header(key, tokens, source, line)
        result.header.setdefault(key, []).extend(tokens)


_REGION = ("from_x", "from_y", "to_x", "to_y")


def _cairn(tokens: list[str], line: int, source: str) -> MapObject:
    """``Type x y th "desc" icon "name" [fromX fromY toX toY]`` (mm, degrees)."""
    if len(tokens) < 7:
        hint = ("; a field holds a quote: a quoted field ends only at a quote before a space "
                "or the line's end" if any('"' in token for token in tokens) else "")
        raise MapError(source, line, f"Cairn needs at least 7 fields (type x y heading "
                                     f"\"description\" icon \"name\"), found {len(tokens)}{hint}")
    kind, name = tokens[0], tokens[6]
    what = f"Cairn {kind} {name!r}" if name else f"Cairn {kind}"
    x, y = (coordinate(tokens[index], what, field, source, line)
            for index, field in ((1, "x"), (2, "y")))
    heading = coordinate(tokens[3], what, "heading", source, line, unit="degrees")
    region = None
    if len(tokens) >= 11:
        fx, fy, tx, ty = (coordinate(token, what, field, source, line) / 1000
                          for token, field in zip(tokens[7:11], _REGION, strict=True))
        region = (fx, fy, tx, ty)
    return MapObject(kind=kind, x=x / 1000, y=y / 1000, theta=math.radians(heading),
                     description=tokens[4], icon=tokens[5], name=name, region=region,
                     line=line)


def _store_section(result: ArnlMap, section: str | None, rows: list[str], lines: list[int],
                   source: str) -> None:
    if section is None:
        return
    width = 4 if section.endswith("LINES") else 2
    array = _numbers(rows, width, lines, source, section) / 1000.0
    if section == "LINES":
        result.lines = array
    elif section == "DATA":
        result.points = array
    elif width == 4:
        result.sensor_lines[section.removesuffix("_LINES")] = array
    else:
        result.sensor_points[section.removesuffix("_DATA")] = array


_FIELDS = {2: ("x", "y"), 4: ("x1", "y1", "x2", "y2")}
_ROWS_AT_ONCE = 65_536  # rows converted together: few temporary objects, whatever the file


def _numbers(rows: list[str], width: int, lines: list[int], source: str,
             section: str) -> np.ndarray:
    """Rows of ``width`` coordinates (mm) as an array.

    A bad row is named by its line, and a number that is not finite or lies beyond the bound by
    its line and field too.

    Rows are converted a block at a time, joined and split once per block: millions of
    per-row lists kept alive at once would cost seconds of garbage collection and gigabytes.
    """
    for index, row in enumerate(rows):  # each list is freed at once
        if len(row.split()) != width:
            raise MapError(source, lines[index], f"{section}: expected {width} numbers, found "
                                                 f"{row[:60]!r}")
    blocks = [np.zeros((0, width))]
    for start in range(0, len(rows), _ROWS_AT_ONCE):
        block = rows[start:start + _ROWS_AT_ONCE]
        tokens = " ".join(block).split()
        try:
            values = np.fromiter(map(float, tokens), dtype=np.float64, count=len(tokens))
        except ValueError:  # name the culprit's line
            for index, token in enumerate(tokens):
                _number(token, width, section, source, lines[start + index // width],
                        block[index // width])
            raise
        outside = ~(np.abs(values) <= MAX_COORDINATE_MM)  # NaN compares false
        if outside.any():
            index = int(np.argmax(outside))
            row_index, column = divmod(index, width)
            raise MapError(source, lines[start + row_index], out_of_bounds(
                section, _FIELDS[width][column], tokens[index]))
        blocks.append(values.reshape(-1, width))
    return np.concatenate(blocks)


def _number(token: str, width: int, section: str, source: str, line: int, row: str) -> None:
    try:
        float(token)
    except ValueError:
        raise MapError(source, line, f"{section}: expected {width} numbers, found "
                                     f"{row[:60]!r}") from None
