"""``cyborg report`` given recordings built to hold it up: a bag whose ``metadata.yaml`` nests
5,000 deep, lists thousands of files or has a syntax error, an MCAP file whose schema has tens
of thousands of fields or with more channels than a recording may define. Each is refused in
one line, or reported with the topic it cannot read named under Log."""

from __future__ import annotations

import html
from pathlib import Path

import pytest
from mcap.writer import Writer

from cyborg.app.cli import main
from cyborg.record.recorded import MAX_SCHEMA_FIELDS
from cyborg.report.build import build_report
from tests.record.bad_recordings import BAD_BAGS, STRING, many_channels, small_recording, wide
from tests.report.page_reader import read_page


@pytest.mark.parametrize("name", sorted(BAD_BAGS))
def test_a_hostile_bag_folder_is_refused_in_one_line(
        tmp_path: Path, name: str, capsys: pytest.CaptureFixture[str]) -> None:
    make, said = BAD_BAGS[name]
    folder = make(tmp_path)
    assert main(["report", str(folder), "-o", str(tmp_path / "run.html")]) == 1
    error = capsys.readouterr().err
    assert error.startswith(f"cyborg: error: {folder}") and said in error
    assert error.count("\n") == 1 and len(error) < 300
    assert not (tmp_path / "run.html").exists()


def test_a_schema_of_40000_fields_is_named_under_log_and_the_rest_reported(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    def wide_topic(writer: Writer) -> None:
        schema = writer.register_schema("their_msgs/msg/Wide", "ros2msg", wide(40_000).encode())
        channel = writer.register_channel("/wide", "cdr", schema)
        writer.add_message(channel, 1_000_000_000, bytes(4), 1_000_000_000)
    path = small_recording(tmp_path / "run.mcap", extra=wide_topic)
    why = (f"their_msgs/msg/Wide: a definition of more than {MAX_SCHEMA_FIELDS:,} fields, the "
           "most one may declare (its constants and the types it uses counted)")
    text = build_report(path)
    assert "21 on 2 topics" in read_page(text).one("table", "meta").all_text()
    assert f"/wide: {html.escape(why)}" in text
    assert main(["report", str(path), "-o", str(tmp_path / "run.html")]) == 0
    assert capsys.readouterr().out.splitlines()[1] == (f"cyborg report: not read, 1 topic: "
                                                       f"/wide ({why})")


def test_channels_up_to_the_bound_are_reported_one_past_it_refused(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = many_channels(tmp_path / "run.mcap")
    assert main(["report", str(path), "-o", str(tmp_path / "run.html")]) == 1
    assert capsys.readouterr().err.startswith(
        f"cyborg: error: {path}: more than the 10,000 channels a recording may define")
    path = many_channels(tmp_path / "edge.mcap", 10_000)
    assert main(["report", str(path), "-o", str(tmp_path / "edge.html")]) == 0
    assert "(1 messages on 10000 topics)" in capsys.readouterr().out
    assert STRING in (tmp_path / "edge.html").read_text()
