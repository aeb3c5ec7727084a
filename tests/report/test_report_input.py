"""What the report makes of files that are not whole recordings, and of a large map; the CLI."""

from __future__ import annotations

import html
import re
from pathlib import Path

import pytest

from cyborg.app.cli import main
from cyborg.bus.msgs.geometry_msgs.msg import Pose2D
from cyborg.nav.arnl_map import read_map
from cyborg.nav.map_message import map_geometry
from cyborg.record.playback_source import RecordingError
from cyborg.record.scan import scan
from cyborg.report.build import build_report
from cyborg.report.map_svg import MAX_POINT_CELLS
from tests.conftest import shared_dir
from tests.record.bad_recordings import (
    REFUSED,
    STRANGE_TOPICS,
    refused,
    sqlite_bag,
    with_strange_schemas,
)
from tests.report.page_reader import polyline_points, read_page
from tests.report.recordings import RecordingWriter, mission


@pytest.mark.parametrize("name", sorted(REFUSED))
def test_a_file_that_is_no_recording_is_refused_in_one_line_naming_it_and_why(
        tmp_path: Path, name: str, capsys: pytest.CaptureFixture[str]) -> None:
    path, said = refused(name, tmp_path)
    with pytest.raises(RecordingError, match=re.escape(said)) as caught:
        build_report(path)
    assert str(caught.value).startswith(f"{path}: ")
    assert main(["report", str(path), "-o", str(tmp_path / "run.html")]) == 1
    error = capsys.readouterr().err
    assert error == f"cyborg: error: {caught.value}\n"
    assert not (tmp_path / "run.html").exists()


def test_a_ros2_bag_folder_is_reported_as_a_recording_is(tmp_path: Path) -> None:
    text = build_report(sqlite_bag(tmp_path / "bag", messages=7))
    page = read_page(text)
    meta = page.one("table", "meta").all_text()
    assert "7 on 1 topics" in meta and "/chatter" in text


def test_topics_that_cannot_be_read_are_named_under_log_and_the_rest_reported(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = with_strange_schemas(tmp_path / "run.mcap")
    text = build_report(path)
    assert "25 on 6 topics" in read_page(text).one("table", "meta").all_text()
    for topic, word in STRANGE_TOPICS.items():
        assert f"{topic}: " in text and html.escape(word) in text
    assert main(["report", str(path)]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[1].startswith(f"cyborg report: not read, {len(STRANGE_TOPICS)} topics: ")
    assert all(f"{topic} (" in lines[1] and word in lines[1]
               for topic, word in STRANGE_TOPICS.items())


def test_a_cut_file_is_reported_as_far_as_it_is_readable_saying_it_was_cut(
        tmp_path: Path) -> None:
    path = tmp_path / "cut.mcap"
    writer = RecordingWriter(path, compression="none")
    for step in range(100):
        writer.add("/cyborg/pose", Pose2D(x=step * 0.1, y=0.0, theta=0.0), step * 0.5)
        if step == 49:
            writer.file.flush()  # the first chunk: poses 0-49
    writer.file.flush()
    data = path.read_bytes()
    writer.close()
    second = scan(path).chunks[1]
    path.write_bytes(data[:second.offset + second.length // 2])  # kill -9 within chunk 2
    page = read_page(build_report(path))
    cut = page.one("p", "cut").all_text()
    assert "This file was cut (a record cut short" in cut
    assert len(polyline_points(page.one("polyline", "trajectory"))) == 50
    assert "50 on 1 topics" in page.one("table", "meta").all_text()


def test_columbias_map_keeps_the_page_small(tmp_path: Path) -> None:
    path = tmp_path / "columbia.mcap"
    geometry = map_geometry(read_map(shared_dir() / "maps" / "columbia.map"))
    assert len(geometry.points) // 2 > 60_000
    writer = RecordingWriter(path)
    writer.add("/cyborg/map_geometry", geometry, 0.0)
    for step in range(20_000):
        writer.add("/cyborg/pose", Pose2D(x=step * 0.01, y=step * 0.002, theta=0.0),
                   step * 0.1)
    writer.close()
    text = build_report(path)
    page = read_page(text)
    assert len(text.encode()) < 3_000_000
    cells = int(page.one("path", "points").attrs["data-cells"])
    assert 1000 < cells <= MAX_POINT_CELLS
    assert len(polyline_points(page.one("polyline", "trajectory"))) <= 5001


def test_cyborg_report_writes_the_page_beside_the_recording(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "run.mcap"
    mission(path)
    assert main(["report", str(path)]) == 0
    out = capsys.readouterr().out
    assert f"report of {path} (128 messages on 11 topics) written to {tmp_path / 'run.html'}" \
        in out
    assert "<h1>Run report: run.mcap</h1>" in (tmp_path / "run.html").read_text()
    assert main(["report", str(path), "-o", str(tmp_path / "elsewhere.html")]) == 0
    assert (tmp_path / "elsewhere.html").stat().st_size > 10_000


def test_cyborg_report_says_what_is_wrong_in_one_line(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "notes.mcap"
    path.write_text("not a recording\n")
    assert main(["report", str(path)]) == 1
    assert capsys.readouterr().err == (f"cyborg: error: {path}: a text file (it does not start "
                                       "with the MCAP magic bytes)\n")
    assert not (tmp_path / "notes.html").exists()
    assert main(["report", str(path), "-o", str(path)]) == 1
    assert "would overwrite the recording" in capsys.readouterr().err
