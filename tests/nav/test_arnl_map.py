"""Reading ARNL maps: the real files in ../shared/maps and broken ones the tests write."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from cyborg.nav.arnl_map import MapError, parse_map, read_map


def test_columbia_counts_and_bounds(shared: Path) -> None:
    arnl_map = read_map(shared / "maps" / "columbia.map")
    assert len(arnl_map.points) == int(arnl_map.header["NumPoints"][0]) == 63311
    assert len(arnl_map.lines) == int(arnl_map.header["NumLines"][0]) == 470
    assert len(arnl_map.objects) == 25
    assert len(arnl_map.forbidden_lines()) == 12 and len(arnl_map.forbidden_areas()) == 2
    assert len(arnl_map.goals()) == 10 and not arnl_map.docks()
    min_pos = [float(value) / 1000 for value in arnl_map.header["MinPos"]]
    max_pos = [float(value) / 1000 for value in arnl_map.header["MaxPos"]]
    assert arnl_map.points.min(axis=0).tolist() == min_pos
    assert arnl_map.points.max(axis=0).tolist() == max_pos
    assert arnl_map.header["OriginLatLongAlt"] == ["42.807191", "-71.578661", "72.000000"]
    lobby = arnl_map.goal("Lobby door")  # quoted name with a space, heading in radians
    assert lobby.kind == "GoalWithHeading" and lobby.has_heading
    assert lobby.theta == pytest.approx(math.radians(-48.5763))
    assert (lobby.x, lobby.y) == (-1.86, -22.44)
    assert not arnl_map.goal("Goal 1").has_heading


def test_amroffice_dock_boxes_and_declared_types(shared: Path) -> None:
    arnl_map = read_map(shared / "maps" / "AMROffice.map")
    assert len(arnl_map.points) == 23181 and len(arnl_map.lines) == 243
    (dock,) = arnl_map.docks()
    assert dock.name == "Dock" and dock.theta == pytest.approx(math.radians(-91.9))
    assert [item.name for item in arnl_map.goals()] == [
        "Dock", "Outside", "room4", "Far Away", "room2", "room1"]
    assert len(arnl_map.forbidden_lines()) == 7
    boxes = arnl_map.sim_obstacles()
    assert len(boxes) == 5 and boxes[0].region == (-5.925, 13.406, -5.425, 13.906)
    names = {declared.name for declared in arnl_map.types}
    assert {"Dock", "DockPioneer", "Sim.BoxObstacle", "Reflector"} <= names


def test_small_line_maps(shared: Path) -> None:
    triangle = read_map(shared / "maps" / "triangle.map")
    assert len(triangle.lines) == 9 and len(triangle.points) == 0
    (home,) = triangle.homes()
    assert home.name == "Home" and home.theta == pytest.approx(math.radians(54))
    assert (home.x, home.y) == (5.09, 3.58)
    for name in ("office.map", "ActivMediaLab.map"):
        assert len(read_map(shared / "maps" / name).lines) > 50


def test_forbidden_area_rotates_about_the_map_origin() -> None:
    arnl_map = parse_map('2D-Map\nCairn: ForbiddenArea 0 0 90.000000 "" ICON "" '
                         '-67552 5362 -55700 13464\n')
    (area,) = arnl_map.forbidden_areas()
    corners = area.corners()
    assert corners is not None
    np.testing.assert_allclose(corners[0], (-5.362, -67.552), atol=1e-9)
    np.testing.assert_allclose(corners[2], (-13.464, -55.700), atol=1e-9)
    assert area.contains(-9.0, -60.0)  # inside once rotated
    assert not area.contains(-60.0, 9.0)  # where the raw corners would put it


def test_custom_types_from_mapinfo_and_sensor_sections() -> None:
    text = """2D-Map-Ex
MapInfo: GoalType Name=Waypoint "Label=Way point"
MapInfo: DockType Name=DockPioneer
Cairn: Waypoint 1000 2000 45 "a desc" ICON "wp 1"
Cairn: DockPioneer 0 0 90 "" ICON "charger"
Cairn: BadGPSSector 0 0 0 "" ICON "" 0 0 1000 1000
LINES
0 0 1000 0
DATA
5 5
Laser2_DATA
1 2
"""
    arnl_map = parse_map(text)
    assert [item.name for item in arnl_map.goals()] == ["wp 1", "charger"]
    assert arnl_map.goal("wp 1").description == "a desc"
    assert arnl_map.docks()[0].theta == pytest.approx(math.pi / 2)
    assert not arnl_map.forbidden_areas()  # an undeclared sector does not block
    assert arnl_map.sensor_points["Laser2"].tolist() == [[0.001, 0.002]]


@pytest.mark.parametrize(("text", "line", "words"), [
    ("", 0, "empty file"),
    ("P2\n3 3\n", 1, "expected '2D-Map'"),
    ('2D-Map\nMinPos: 0 0\nCairn: Goal 1 2 "" ICON\n', 3, "at least 7 fields"),
    ('2D-Map\nCairn: Goal x 2 0 "" ICON "a"\n', 2, "not a number"),
    ('2D-Map\nCairn: Goal 1 2 0 "unclosed ICON "a"\n', 2, "quote"),
    ("2D-Map\nLINES\n0 0 1 1\n0 0 1\n", 4, "expected 4 numbers"),
    ("2D-Map\nDATA\n1 2\n\n3 abc\n", 5, "expected 2 numbers"),
    ("2D-Map\nnot a key line\n", 2, "Key: values"),
])
def test_bad_maps_name_the_line(text: str, line: int, words: str) -> None:
    with pytest.raises(MapError) as caught:
        parse_map(text, "bad.map")
    assert caught.value.line == line and words in str(caught.value)
    assert str(caught.value).startswith(f"bad.map:{line}:" if line else "bad.map:")


def test_missing_file_is_a_map_error(tmp_path: Path) -> None:
    with pytest.raises(MapError, match=r"nope\.map: cannot read the map"):
        read_map(tmp_path / "nope.map")


def test_unknown_goal_lists_the_names(shared: Path) -> None:
    arnl_map = read_map(shared / "maps" / "AMROffice.map")
    with pytest.raises(KeyError, match=r"no goal named 'kitchen'.*'room1'"):
        arnl_map.goal("kitchen")


# ---------------------------------------------------------------------- bytes on disk
def test_a_byte_order_mark_changes_nothing(shared: Path, tmp_path: Path) -> None:
    original = shared / "maps" / "columbia.map"
    copy = tmp_path / "columbia.map"
    copy.write_bytes(b"\xef\xbb\xbf" + original.read_bytes())  # as a public copy has it
    plain, marked = read_map(original), read_map(copy)
    assert marked.intro == "2D-Map" and marked.header == plain.header
    assert marked.objects == plain.objects  # same kinds, names, poses and line numbers
    np.testing.assert_array_equal(marked.points, plain.points)
    np.testing.assert_array_equal(marked.lines, plain.lines)
    assert parse_map("\ufeff2D-Map\nDATA\n1 2\n").points.tolist() == [[0.001, 0.002]]


NORDIC = '2D-Map\nCairn: Goal 1000 2000 0 "Stue øst" ICON "Kjøkken"\n' \
         'Cairn: GoalWithHeading 0 0 90 "" ICON "Åpent område"\nDATA\n'


@pytest.mark.parametrize("encoding", ["latin-1", "cp1252", "utf-8", "utf-8-sig", "utf-16"])
def test_non_ascii_names_read_right_in_any_encoding_arnl_tools_write(
        tmp_path: Path, encoding: str) -> None:
    path = tmp_path / "nordic.map"
    path.write_bytes(NORDIC.encode(encoding))
    arnl_map = read_map(path)
    assert [item.name for item in arnl_map.goals()] == ["Kjøkken", "Åpent område"]
    assert arnl_map.goal("Kjøkken").description == "Stue øst"


def test_windows_punctuation_and_mixed_lines(tmp_path: Path) -> None:
    """A Windows editor writes "…" as byte 0x85, which Latin-1 would make a line break; a
    file edited by two tools may hold UTF-8 and Latin-1 lines side by side."""
    path = tmp_path / "mixed.map"
    path.write_bytes(b'2D-Map\nCairn: Goal 0 0 0 "" ICON "Kaffe\x85"\n'
                     + 'Cairn: Goal 0 0 0 "" ICON "Møterom"\n'.encode()
                     + b'Cairn: Goal 0 0 0 "" ICON "Sm\xf8rbr\xf8d"\nnot a key\n')
    with pytest.raises(MapError) as caught:
        read_map(path)
    assert caught.value.line == 5  # 0x85 did not split line 2
    path.write_bytes(path.read_bytes().removesuffix(b"not a key\n"))
    assert [item.name for item in read_map(path).goals()] == ["Kaffe…", "Møterom", "Smørbrød"]


@pytest.mark.parametrize("encoding", ["latin-1", "utf-8"])
@pytest.mark.parametrize(("row", "words"), [
    ('Cairn: Goal 1x 2000 0 "" ICON "Kjøkken"', "Cairn Goal 'Kjøkken': a coordinate"),
    ("Stue øst", "found 'Stue øst'"),
])
def test_bad_line_in_a_non_ascii_file_names_file_and_line_without_mojibake(
        tmp_path: Path, encoding: str, row: str, words: str) -> None:
    path = tmp_path / "nordic.map"
    path.write_bytes(f"2D-Map\nResolution: 20\n{row}\nDATA\n".encode(encoding))
    with pytest.raises(MapError) as caught:
        read_map(path)
    message = str(caught.value)
    assert message.startswith(f"{path}:3: ") and words in message
    assert "Ã" not in message and "\\x" not in message


def test_broken_utf16_is_a_map_error(tmp_path: Path) -> None:
    path = tmp_path / "half.map"
    path.write_bytes("2D-Map\n".encode("utf-16")[:-1])  # odd length: cut mid-character
    with pytest.raises(MapError, match=r"half\.map: starts with a UTF-16 byte-order mark"):
        read_map(path)
