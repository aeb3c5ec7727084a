"""Bad input to the reader that ``cyborg play`` and ``cyborg report`` share: what is no recording
is refused with one line naming the file and what is wrong; a recording with topics it cannot
play plays the rest and names them; random damage to a valid file never raises anything but
:class:`~cyborg.record.playback_source.RecordingError`."""

from __future__ import annotations

import tempfile
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from mcap.writer import Writer

from cyborg.bus import MessageTypes
from cyborg.record.playback_source import RecordingError, open_recording
from cyborg.report.recording import read_recording
from tests.record.bad_recordings import (
    REFUSED,
    STRANGE_TOPICS,
    cut_in_its_middle,
    refused,
    small_recording,
    with_strange_schemas,
)


@pytest.mark.parametrize("name", sorted(REFUSED))
def test_what_is_no_recording_is_refused_in_one_line_naming_the_file(tmp_path: Path,
                                                                     name: str) -> None:
    path, said = refused(name, tmp_path)
    with pytest.raises(RecordingError) as raised:
        open_recording(path, MessageTypes())
    assert str(raised.value).startswith(f"{path}: ")
    assert said in str(raised.value) and "\n" not in str(raised.value)


def test_a_ros1_bag_named_mcap_is_told_to_be_renamed_and_then_plays(tmp_path: Path) -> None:
    path, _said = refused("ros1 bag named .mcap", tmp_path)
    with pytest.raises(RecordingError, match=r"rename it to \.bag to read it as one"):
        open_recording(path, MessageTypes())
    recording = open_recording(path.rename(path.with_suffix(".bag")), MessageTypes())
    try:
        assert [p.topic for p in recording.messages()] == ["/chatter"]
    finally:
        recording.close()


def test_topics_with_unknown_empty_or_missing_schemas_are_named_and_the_rest_plays(
        tmp_path: Path) -> None:
    recording = open_recording(with_strange_schemas(tmp_path / "run.mcap"), MessageTypes())
    try:
        assert set(recording.topics) == {"/chatter"}
        assert set(recording.skipped) == set(STRANGE_TOPICS)
        for topic, word in STRANGE_TOPICS.items():
            assert word in recording.skipped[topic] and "\n" not in recording.skipped[topic]
            assert recording.unplayed[topic].count == 1
        assert {played.topic for played in recording.messages()} == {"/chatter"}
    finally:
        recording.close()


def test_a_file_cut_in_its_middle_plays_its_whole_chunks_and_says_where_it_was_cut(
        tmp_path: Path) -> None:
    whole = small_recording(tmp_path / "whole.mcap")
    recording = open_recording(cut_in_its_middle(whole, tmp_path / "cut.mcap"), MessageTypes())
    try:
        played = [p.log_time for p in recording.messages()]
        assert recording.cut is not None and "cut short" in recording.cut
        assert 0 < len(played) < 20 and played == sorted(played)
        assert recording.topics["/chatter"].count == len(played)
    finally:
        recording.close()


def _fuzzed_base() -> bytes:
    """A small valid recording with a latched topic, metadata and a skipped topic."""
    def more(writer: Writer) -> None:
        writer.add_metadata("cyborg", {"cyborg_version": "0", "map": "a.map"})
        latched = writer.register_channel(
            "/map", "cdr", writer.register_schema("std_msgs/msg/Empty", "ros2msg", b""),
            {"offered_qos_profiles": "- durability: transient_local\n"})
        writer.add_message(latched, 1_000_000_000, b"\x00\x01\x00\x00", 1_000_000_000)
        writer.register_channel("/json", "json", writer.register_schema("J", "jsonschema",
                                                                        b"{}"))
    with tempfile.TemporaryDirectory() as folder:
        return small_recording(Path(folder) / "base.mcap", chatter=12, extra=more).read_bytes()


BASE = _fuzzed_base()

damage = st.one_of(
    st.tuples(st.just("flip"), st.integers(0, len(BASE) - 1), st.integers(1, 255)),
    st.tuples(st.just("cut"), st.integers(0, len(BASE) - 1), st.just(0)),
    st.tuples(st.just("drop"), st.integers(0, len(BASE) - 1), st.integers(1, 64)),
    st.tuples(st.just("insert"), st.integers(0, len(BASE) - 1), st.integers(0, 255)),
    st.tuples(st.just("zero"), st.integers(0, len(BASE) - 1), st.integers(1, 512)),
)


def damaged(changes: list[tuple[str, int, int]]) -> bytes:
    """``BASE`` with each change made in turn: a byte flipped, an end cut, bytes dropped,
    a byte inserted, or a run of zeros written (a power loss)."""
    data = bytearray(BASE)
    for kind, where, value in changes:
        where = min(where, max(len(data) - 1, 0))
        if kind == "flip" and data:
            data[where] ^= value
        elif kind == "cut":
            del data[where:]
        elif kind == "drop":
            del data[where:where + value]
        elif kind == "insert":
            data.insert(where, value)
        elif kind == "zero":
            data[where:where + value] = bytes(len(data[where:where + value]))
    return bytes(data)


@settings(max_examples=200, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(changes=st.lists(damage, min_size=1, max_size=4))
def test_a_damaged_recording_raises_nothing_but_a_recording_error(
        tmp_path: Path, changes: list[tuple[str, int, int]]) -> None:
    path = tmp_path / "run.mcap"
    path.write_bytes(damaged(changes))
    try:
        recording = open_recording(path, MessageTypes())
    except RecordingError as exc:
        assert str(exc).startswith(f"{path}: ")
        return
    try:
        played = list(recording.messages())
        assert len(played) <= sum(topic.count for topic in recording.topics.values())
        recording.latched_before(recording.end_ns + 1)
        assert all(isinstance(name, str) for name, _values in recording.metadata)
    finally:
        recording.close()
    report = read_recording(path, lambda _topic, _type: True)
    assert report.message_count >= len(played)
