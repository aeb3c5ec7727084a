"""Hostile and broken ARNL maps: every one loads or is a MapError naming file and line, fast.

The attacks of issue 19 (item 11) first, each as it was found; then the same kinds of defect
elsewhere in the reader and the grid; then hypothesis throws generated and garbage maps at the
whole chain (read, rasterise, plan) and expects a map or a located MapError within seconds.
"""

from __future__ import annotations

import os
import shlex
import threading
import time
from pathlib import Path

import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from cyborg.nav.arnl_map import MapError, parse_map, read_map, split_fields
from cyborg.nav.geometry import Pose2D
from cyborg.nav.grid import MapGrid
from cyborg.nav.map_limits import map_limits
from cyborg.nav.map_syntax import MAX_COORDINATE_MM
from cyborg.nav.planner import Planner
from tests.small_maps import room_map

ROOM = room_map([])


def with_row(row: str) -> str:
    """The test room with ``row`` as line 3 (after ``2D-Map`` and ``Resolution: 20``)."""
    first, second, rest = ROOM.split("\n", 2)
    return f"{first}\n{second}\n{row}\n{rest}"


# ---------------------------------------------------------------------- item 11: coordinates
@pytest.mark.parametrize(("row", "field"), [
    ('Cairn: ForbiddenArea 0 0 0 "" ICON "" nan 0 1000 1000', "from_x"),
    ('Cairn: ForbiddenArea 0 0 0 "" ICON "" 0 inf 1000 1000', "from_y"),
    ('Cairn: ForbiddenArea 0 0 0 "" ICON "" 0 0 1e300 1000', "to_x"),
    ('Cairn: RobotHome 0 0 0 "" ICON "" 0 0 1000 -1e9', "to_y"),
    ('Cairn: Goal nan 0 0 "" ICON "a"', "x"),
    ('Cairn: Goal 0 1e300 0 "" ICON "a"', "y"),
    ('Cairn: GoalWithHeading 0 0 inf "" ICON "a"', "heading"),
    ('Cairn: GoalWithHeading 0 0 1e300 "" ICON "a"', "heading"),
    ('Cairn: Dock 1000000000 0 0 "" ICON "far"', "x"),
    ("Resolution: nan", "Resolution"),
    ("Resolution: -20", "Resolution"),
    ("LineMinPos: 0 1e300", "LineMinPos"),
    ("MaxPos: inf 0", "MaxPos"),
    ("MinPos: 0", "MinPos"),
    ("NumPoints: -5", "NumPoints"),
    ("NumLines: 1.5", "NumLines"),
    ("OriginLatLongAlt: 91 0 0", "OriginLatLongAlt"),
    ("OriginLatLongAlt: 0 nan 0", "OriginLatLongAlt"),
])
def test_non_finite_or_far_coordinates_are_located_errors(row: str, field: str) -> None:
    """NaN, infinity and 1e300 used to load, list under ``nav goals``, and crash the planner
    and the simulator with "cannot convert float NaN to integer"."""
    with pytest.raises(MapError) as caught:
        parse_map(with_row(row), "bad.map")
    message = str(caught.value)
    assert caught.value.line == 3 and message.startswith("bad.map:3: "), message
    assert field in message, message
    assert "\n" not in message


@pytest.mark.parametrize(("section", "row", "field"), [
    ("DATA", "1e300 0", "x"),
    ("DATA", "0 nan", "y"),
    ("DATA", "1000000000 0", "x"),  # 1e9 mm: the 4.5 GiB grid
    ("LINES", "0 0 inf 1", "x2"),
    ("LINES", "0 0 1 -20000000", "y2"),
])
def test_points_and_lines_beyond_the_bound_name_line_and_field(
        section: str, row: str, field: str) -> None:
    text = f"2D-Map\n{section}\n0 {'0 1 1' if section == 'LINES' else '0'}\n{row}\n"
    with pytest.raises(MapError) as caught:
        parse_map(text, "bad.map")
    assert caught.value.line == 4
    assert f"{section}: {field} " in str(caught.value)
    assert f"{MAX_COORDINATE_MM:.0f}" in str(caught.value)


def test_the_bound_itself_is_a_coordinate_and_headings_may_turn_many_times() -> None:
    text = ('2D-Map\nCairn: GoalWithHeading 10000000 0 3600 "" ICON "far"\n'
            'Cairn: GoalWithHeading 10000000 0 -1e7 "" ICON "spun"\nDATA\n10000000 0\n')
    arnl_map = parse_map(text)
    assert [goal.name for goal in arnl_map.goals()] == ["far", "spun"]
    assert arnl_map.goal("far").x == MAX_COORDINATE_MM / 1000


def test_a_map_too_large_for_the_grid_names_file_extent_cap_and_how_to_raise() -> None:
    """9 km by 9 km is within the coordinate bound but would be 3e10 cells at 5 cm."""
    text = "2D-Map\nDATA\n0 0\n9000000 9000000\n"
    started = time.perf_counter()
    with pytest.raises(MapError) as caught:
        parse_map(text, "huge.map")
    assert time.perf_counter() - started < 1.0
    message = str(caught.value)
    assert message.startswith("huge.map: ")
    assert "9002.0 m x 9002.0 m" in message and "cells" in message
    assert f"{map_limits().max_cells:,}" in message and "CYBORG_MAP_MAX_CELLS" in message


def test_the_cell_cap_can_be_raised_and_applies_to_finer_grids(
        monkeypatch: pytest.MonkeyPatch) -> None:
    text = "2D-Map\nDATA\n0 0\n60000 60000\n"  # 62 m square with the margin: 1.5 M cells
    monkeypatch.setenv("CYBORG_MAP_MAX_CELLS", "1000000")
    with pytest.raises(MapError, match="more than the cap of 1,000,000"):
        parse_map(text, "big.map")
    monkeypatch.setenv("CYBORG_MAP_MAX_CELLS", "2000000")
    arnl_map = parse_map(text, "big.map")
    with pytest.raises(MapError, match=r"big\.map: .* at 0\.01 m"):
        MapGrid.from_map(arnl_map, 0.01)  # 39 M cells


def test_drawing_many_long_walls_is_capped_before_it_starts() -> None:
    """Every line is drawn cell by cell: 20,000 diagonals across a 150 m map would be 4e8
    samples (tens of GiB), far beyond any real map's walls."""
    rows = "\n".join("0 0 150000 150000" for _ in range(20_000))
    started = time.perf_counter()
    with pytest.raises(MapError) as caught:
        parse_map(f"2D-Map\nLINES\n{rows}\n", "walls.map")
    assert time.perf_counter() - started < 3.0
    assert "walls.map: " in str(caught.value) and "CYBORG_MAP_MAX_CELLS" in str(caught.value)


# ---------------------------------------------------------------------- item 11: parsing time
def test_a_long_quoted_field_parses_in_linear_time() -> None:
    """A 5 MB quoted description took over 120 s with shlex (quadratic)."""
    description = "a" * 5_000_000
    started = time.perf_counter()
    arnl_map = parse_map(f'2D-Map\nCairn: Goal 0 0 0 "{description}" ICON "g"\n')
    assert time.perf_counter() - started < 5.0
    assert len(arnl_map.goal("g").description) == 5_000_000


@pytest.mark.parametrize("unit", ['"x ', 'x" ', '" ', '"a" ', "\\ "])
def test_lines_of_quotes_parse_in_linear_time(unit: str) -> None:
    row = "MapInfo: GoalType " + unit * 400_000
    started = time.perf_counter()
    try:
        parse_map(f"2D-Map\n{row}\n", "quotes.map")
    except MapError as exc:
        assert exc.line == 2
    assert time.perf_counter() - started < 5.0


def test_many_declared_types_and_objects_classify_in_linear_time() -> None:
    types = "\n".join(f"MapInfo: GoalType Name=T{i}" for i in range(5000))
    cairns = "\n".join(f'Cairn: T{i} 0 0 0 "" ICON "g{i}"' for i in range(5000))
    started = time.perf_counter()
    arnl_map = parse_map(f"2D-Map\n{types}\n{cairns}\n")
    assert time.perf_counter() - started < 3.0
    assert len(arnl_map.goals()) == 5000


@pytest.mark.parametrize(("row", "kind"), [('Cairn: Goal 0 0 0 "" ICON "g{}"', "Cairn"),
                                           ("MapInfo: GoalType Name=T{}", "MapInfo"),
                                           ("RouteInfo: Task{}", "other header")])
def test_the_number_of_objects_and_header_lines_is_capped(
        monkeypatch: pytest.MonkeyPatch, row: str, kind: str) -> None:
    monkeypatch.setenv("CYBORG_MAP_MAX_OBJECTS", "100")
    rows = "\n".join(row.format(i) for i in range(101))
    with pytest.raises(MapError) as caught:
        parse_map(f"2D-Map\n{rows}\n", "many.map")
    assert caught.value.line == 102 and f"more than 100 {kind} lines" in str(caught.value)
    assert "CYBORG_MAP_MAX_OBJECTS" in str(caught.value)


def test_a_data_section_at_the_byte_cap_reads_in_seconds() -> None:
    """Rows are converted a block at a time; one list per row kept alive (the old way) cost
    seconds of garbage collection and a gigabyte for a 16 MiB file."""
    text = "2D-Map\nDATA\n" + "1 2\n" * (map_limits().max_bytes // 4 - 4)
    started = time.perf_counter()
    assert len(parse_map(text).points) == map_limits().max_bytes // 4 - 4
    assert time.perf_counter() - started < 10.0


# ---------------------------------------------------------------------- item 11: line ends
@pytest.mark.parametrize(("inside", "expected"), [
    (b"a\x85b\x0cc\x1cd", "a\u2026b\x0cc\x1cd"),  # not UTF-8: 0x85 is Windows-1252's "..."
    ("a\u0085b\u2028c\u2029d\x1d\x1e\x0b".encode(), "a\u0085b\u2028c\u2029d\x1d\x1e\x0b"),
])
def test_control_characters_in_a_description_do_not_split_the_line(
        tmp_path: Path, inside: bytes, expected: str) -> None:
    """``str.splitlines`` ends lines at 0x85, 0x0c, 0x1c-0x1e and U+2028/9 too; ARNL does not."""
    path = tmp_path / "controls.map"
    path.write_bytes(b'2D-Map\nCairn: Goal 0 0 0 "' + inside + b'" ICON "g"\nnot a key\n')
    with pytest.raises(MapError) as caught:
        read_map(path)
    assert caught.value.line == 3  # nothing inside line 2 ended it
    path.write_bytes(path.read_bytes().removesuffix(b"not a key\n"))
    assert read_map(path).goal("g").description == expected


# ---------------------------------------------------------------------- ARNL's quoting rules
def test_fields_split_as_aria_splits_them() -> None:
    """A field that starts with a quote ends at a quote followed by a space or the line's end;
    quotes inside it and backslashes stay; other fields end at whitespace."""
    assert split_fields('GoalType "Name=Goal" Label=Goal') == ["GoalType", "Name=Goal",
                                                               "Label=Goal"]
    assert split_fields('Goal 0 0 0 "the 5"-wide door" ICON "C:\\maps\\"') == [
        "Goal", "0", "0", "0", 'the 5"-wide door', "ICON", "C:\\maps\\"]
    assert split_fields('"" ""\t"a b"') == ["", "", "a b"]
    with pytest.raises(ValueError, match="never closed"):
        split_fields('Goal "unclosed ICON a')


def test_fields_agree_with_the_old_reader_on_every_shared_map(shared: Path) -> None:
    for path in sorted((shared / "maps").glob("*.map")):
        for row in path.read_text(encoding="latin-1").split("\n"):
            key, colon, rest = row.partition(":")
            if colon and (key in ("Cairn", "MapInfo") or key.endswith("Pos")):
                assert split_fields(rest) == shlex.split(rest), (path.name, row)


# ---------------------------------------------------------------------- item 11: the file
def test_the_file_size_is_capped(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    path = tmp_path / "big.map"
    path.write_text("2D-Map\nDATA\n" + "1 2\n" * 500)
    monkeypatch.setenv("CYBORG_MAP_MAX_BYTES", "1000")
    with pytest.raises(MapError) as caught:
        read_map(path)
    message = str(caught.value)
    assert message.startswith(f"{path}: ") and "2,012 bytes" in message
    assert "1,000" in message and "CYBORG_MAP_MAX_BYTES" in message


def test_a_fifo_is_refused_without_waiting(tmp_path: Path) -> None:
    fifo = tmp_path / "pipe.map"
    os.mkfifo(fifo)
    outcome: list[BaseException | None] = []

    def load() -> None:
        try:
            read_map(fifo)
            outcome.append(None)
        except BaseException as exc:  # reported below
            outcome.append(exc)

    worker = threading.Thread(target=load, daemon=True)
    worker.start()
    worker.join(5.0)
    if worker.is_alive():  # unblock the reader, then fail
        with open(fifo, "wb"):
            pass
        worker.join(5.0)
        pytest.fail("read_map waited for a writer on a FIFO")
    assert isinstance(outcome[0], MapError) and "not a regular file" in str(outcome[0])


@pytest.mark.parametrize("name", ["/dev/zero", "/dev/null", "."])
def test_devices_and_folders_are_refused(name: str) -> None:
    with pytest.raises(MapError, match="not a regular file"):
        read_map(name)


def test_a_path_with_a_nul_byte_is_a_map_error() -> None:
    with pytest.raises(MapError, match="cannot read the map"):
        read_map("maps/a\x00b.map")


def test_the_shared_maps_load_as_fast_as_before(shared: Path) -> None:
    started = time.perf_counter()
    for _ in range(3):
        read_map(shared / "maps" / "columbia.map")
    assert (time.perf_counter() - started) / 3 < 0.5  # 0.12 s on a 2-core machine


# ---------------------------------------------------------------------- fuzzing
_SMALL = st.integers(-12_000, 12_000).map(str)
_HOSTILE = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.sampled_from(["nan", "-inf", "1e300", "1e9", "-1e7", "10000001", "0x10", "1_000",
                     "", "+", "-", ".", "e5", "\u0663"]),
)
_NUMBER = st.one_of(_SMALL, _SMALL, _SMALL, _HOSTILE)  # mostly maps that load
_TEXT = st.text(st.characters(codec="utf-8", exclude_characters="\n\r"), max_size=12)
_WORD = st.text(st.characters(codec="utf-8", exclude_characters='\n\r\t\x0b\x0c "'),
               max_size=8)
_QUOTED = st.one_of(_TEXT.map(lambda text: f'"{text}"'), _WORD.map(lambda text: f'"{text}"'),
                    _WORD.filter(bool))
_KINDS = st.sampled_from(["Goal", "GoalWithHeading", "Dock", "RobotHome", "ForbiddenLine",
                          "ForbiddenArea", "Sim.BoxObstacle", "Waypoint", "T0"])


@st.composite
def _cairn(draw: st.DrawFn) -> str:
    fields = [draw(_KINDS), draw(_NUMBER), draw(_NUMBER), draw(_NUMBER), draw(_QUOTED),
              draw(st.sampled_from(["ICON", "ID=1", '""'])), draw(_QUOTED)]
    if draw(st.booleans()):
        fields += [draw(_NUMBER) for _ in range(draw(st.integers(0, 5)))]
    if draw(st.integers(0, 9)) == 0:  # now and then too few fields
        fields = fields[: draw(st.integers(0, len(fields)))]
    return "Cairn: " + " ".join(fields)


_HEADER = st.builds(lambda key, values: f"{key}: {' '.join(values)}",
                    st.sampled_from(["MinPos", "MaxPos", "LineMinPos", "LineMaxPos",
                                     "NumPoints", "NumLines", "Resolution", "OriginLatLongAlt",
                                     "Laser2MinPos", "PointsAreSorted", "Sources", "MetaInfo"]),
                    st.lists(_NUMBER, max_size=4))
_MAPINFO = st.builds(lambda category, settings: f"MapInfo: {category} {' '.join(settings)}",
                     st.sampled_from(["GoalType", "DockType", "SectorType", "BoundaryType", ""]),
                     st.lists(_QUOTED.map(lambda value: f"Name={value}"), max_size=3))
_SECTION = st.builds(lambda name, rows: "\n".join(
    [name, *(" ".join(row[: 4 if name.endswith("LINES") else 2]) for row in rows)]),
                     st.sampled_from(["LINES", "DATA", "Laser2_LINES", "Laser2_DATA"]),
                     st.lists(st.lists(_NUMBER, min_size=4, max_size=4), max_size=6))
_GARBAGE = st.one_of(_TEXT, st.lists(_NUMBER, min_size=1, max_size=5).map(" ".join),
                     st.sampled_from(["", "   ", "LINES", "DATA", "_DATA"]))
_ROW = st.one_of(*[_cairn()] * 5, _HEADER, _MAPINFO, _SECTION, _SECTION, _SECTION, _GARBAGE)


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(intro=st.sampled_from(["2D-Map"] * 8 + ["2D-Map-Ex2", "", "2D-map", "P2"]),
       rows=st.lists(_ROW, max_size=12),
       line_end=st.sampled_from(["\n", "\r\n", "\r"]))
def test_fuzz_generated_map_text_loads_plans_or_names_file_and_line(
        intro: str, rows: list[str], line_end: str) -> None:
    text = line_end.join([intro, *rows]) + line_end
    started = time.perf_counter()
    try:
        arnl_map = parse_map(text, "fuzz.map")
    except MapError as exc:
        assert str(exc).startswith("fuzz.map:") and exc.line >= 0 and "\n" not in str(exc)
        assert time.perf_counter() - started < 5.0
        return
    event("loaded")
    try:
        planner = Planner(arnl_map)
    except MapError as exc:  # a grid the reader let through must still be refused cleanly
        assert str(exc).startswith("fuzz.map:")
        return
    min_x, min_y, max_x, max_y = arnl_map.bounds()
    result = planner.plan(Pose2D(min_x, min_y), Pose2D(max_x, max_y, 1.0))
    assert result.found or result.code
    assert time.perf_counter() - started < 5.0


@settings(max_examples=150, deadline=None)
@given(raw=st.binary(max_size=400), prefix=st.sampled_from([b"", b"2D-Map\n", b"2D-Map\nDATA\n",
                                                             b"\xef\xbb\xbf2D-Map\r\n",
                                                             b"\xff\xfe"]))
def test_fuzz_garbage_bytes_load_or_name_the_file(tmp_path_factory: pytest.TempPathFactory,
                                                  raw: bytes, prefix: bytes) -> None:
    path = tmp_path_factory.getbasetemp() / "garbage.map"
    path.write_bytes(prefix + raw)
    started = time.perf_counter()
    try:
        arnl_map = read_map(path)
    except MapError as exc:
        assert str(exc).startswith(f"{path}:") and "\n" not in str(exc)
    else:
        MapGrid.from_map(arnl_map, 0.1)
    assert time.perf_counter() - started < 5.0


@pytest.mark.parametrize("kind", ["ForbiddenLine", "ForbiddenArea"])
def test_a_forbidden_zone_without_its_region_is_a_located_error(kind: str) -> None:
    text = f'2D-Map\nLineMinPos: 0 0\nCairn: {kind} 0 0 0 "" ICON "zone"\n'
    with pytest.raises(MapError, match=rf"fz.map:3: Cairn {kind} 'zone': a forbidden zone "
                                       "needs its region"):
        parse_map(text, "fz.map")
