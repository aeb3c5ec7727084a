"""Bags built to hold rosbags up: ``metadata.yaml`` nested 5,000 deep, listing thousands of
files or topics, with a syntax error or an alias; definitions of thousands of fields. Each is
refused in one line naming the file (and the line and column, or the topic) before rosbags
reads it, and one within the bounds is read whole."""

from __future__ import annotations

from pathlib import Path

import pytest
from rosbags.rosbag1 import Writer as Ros1Writer
from rosbags.rosbag2 import StoragePlugin
from rosbags.rosbag2 import Writer as Ros2Writer
from rosbags.typesys import Stores, get_typestore
from rosbags.typesys.msg import get_types_from_msg

from cyborg.app.cli import main
from cyborg.bus import MessageTypes
from cyborg.record import bag_checks
from cyborg.record.playback_source import RecordingError, open_recording
from cyborg.record.recorded import MAX_SCHEMA_FIELDS, skipped_line
from tests.record.bad_recordings import BAD_BAGS, wide


@pytest.mark.parametrize("name", sorted(BAD_BAGS))
def test_a_hostile_bag_folder_is_refused_in_one_line_naming_the_file(
        tmp_path: Path, name: str, capsys: pytest.CaptureFixture[str]) -> None:
    make, said = BAD_BAGS[name]
    folder = make(tmp_path)
    with pytest.raises(RecordingError) as raised:
        open_recording(folder, MessageTypes())
    assert str(raised.value).startswith(f"{folder}") and said in str(raised.value)
    assert "\n" not in str(raised.value) and len(str(raised.value)) < 300
    assert main(["play", str(folder), "--connect", "tcp/127.0.0.1:9"]) == 1
    assert capsys.readouterr().err == f"cyborg: error: {raised.value}\n"


def test_missing_files_are_counted_and_the_first_three_named(tmp_path: Path) -> None:
    folder = tmp_path / "bag"
    folder.mkdir()
    (folder / "metadata.yaml").write_text("rosbag2_bagfile_information:\n  relative_file_paths: "
                                          "[a.mcap, b.mcap, c.mcap, d.mcap]\n")
    (folder / "b.mcap").write_bytes(b"")
    with pytest.raises(RecordingError) as raised:
        open_recording(folder, MessageTypes())
    assert str(raised.value) == (f"{folder}: 3 of the 4 files metadata.yaml lists are missing: "
                                 "a.mcap, c.mcap, d.mcap")
    (folder / "metadata.yaml").write_text("rosbag2_bagfile_information:\n  relative_file_paths: "
                                          "[b.mcap, c.mcap]\n")
    with pytest.raises(RecordingError, match=r"1 of the 2 files metadata\.yaml lists is missing: "
                                             r"c\.mcap$"):
        open_recording(folder, MessageTypes())


def _bag_of(folder: Path, topics: dict[str, str], ros1: bool = False) -> Path:
    """A bag (a ROS 2 folder with an MCAP file, or a ROS 1 ``.bag``) with one message on each
    of ``topics``, whose types (name to definition) only the bag defines."""
    if ros1:
        with Ros1Writer(folder) as writer1:
            for topic, (type_name, text) in enumerate(topics.items()):
                connection = writer1.add_connection(f"/t{topic}", type_name, msgdef=text,
                                                    md5sum="0" * 32)
                writer1.write(connection, 1_000, bytes(4))
        return folder
    store = get_typestore(Stores.EMPTY)
    store.register({name: value for type_name, text in topics.items()
                    for name, value in get_types_from_msg(text, type_name).items()})
    with Ros2Writer(folder, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        for topic, (type_name, text) in enumerate(topics.items()):
            connection = writer.add_connection(f"/t{topic}", type_name, msgdef=text,
                                               rihs01=store.hash_rihs01(type_name))
            writer.write(connection, 1_000, b"\x00\x01\x00\x00" + bytes(8000))
    return folder


@pytest.mark.parametrize("ros1", [False, True], ids=["ros2 folder", "ros1 bag"])
def test_a_bag_whose_definition_passes_the_bounds_is_refused_before_rosbags_reads_it(
        tmp_path: Path, ros1: bool) -> None:
    bag = _bag_of(tmp_path / ("run.bag" if ros1 else "bag"),
                  {"their_msgs/msg/Small": wide(3),
                   "their_msgs/msg/Wide": wide(MAX_SCHEMA_FIELDS + 1)}, ros1)
    with pytest.raises(RecordingError) as raised:
        open_recording(bag, MessageTypes())
    assert str(raised.value) == (
        f"{bag}: topic /t1: their_msgs/msg/Wide: a definition of more than "
        f"{MAX_SCHEMA_FIELDS:,} fields, the most one may declare (its constants and the types "
        "it uses counted)")


def test_a_bags_definitions_are_bounded_together_as_rosbags_reads_one_per_topic(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    types = {f"their_msgs/msg/T{number}": wide(9) for number in range(3)}  # 10 lines each
    monkeypatch.setattr(bag_checks, "MAX_DEFINITION_LINES", 29)
    bag = _bag_of(tmp_path / "bag", types)
    with pytest.raises(RecordingError, match=r"pass 29 lines \(at topic /t2\)$"):
        open_recording(bag, MessageTypes())
    monkeypatch.setattr(bag_checks, "MAX_DEFINITION_LINES", 30)
    recording = open_recording(bag, MessageTypes())
    try:
        assert sorted(recording.topics) == ["/t0", "/t1", "/t2"] and not recording.skipped
        assert [played.data[4:] for played in recording.messages()] == [bytes(8000)] * 3
    finally:
        recording.close()


def test_the_line_of_topics_left_out_names_ten_and_counts_the_rest() -> None:
    """A recording may leave out 10,000 topics: play's and report's one line stays short."""
    many = {f"/topic{number:05d}": "unknown type pkg/msg/T" for number in range(10_000)}
    line = skipped_line(many)
    assert line.startswith("10,000 topics: /topic00000 (unknown type pkg/msg/T); /topic00001")
    assert line.endswith("; and 9,990 more") and len(line) < 600
    assert skipped_line({"/a": "x" * 5000}) == f"1 topic: /a ({'x' * 200})"
