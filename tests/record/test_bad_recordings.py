"""Bad input to the reader that ``cyborg play`` and ``cyborg report`` share: what is no recording
is refused with one line naming the file and what is wrong; a recording with topics it cannot
play plays the rest and names them; random damage to a valid file, and hostile shapes (a bag's
``metadata.yaml`` nested deep, edited at random or listing too many files and topics; channels
and schema fields around their bounds), never raise anything but
:class:`~cyborg.record.playback_source.RecordingError`, in one line."""

from __future__ import annotations

import itertools
import tempfile
from pathlib import Path
from unittest import mock

import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from mcap.writer import Writer

from cyborg.bus import MessageTypes
from cyborg.record import recorded
from cyborg.record import scan as scan_module
from cyborg.record.bag_checks import MAX_BAG_FILES, MAX_BAG_TOPICS
from cyborg.record.playback_source import RecordingError, open_recording
from cyborg.report.recording import read_recording
from tests.record.bad_recordings import (
    REFUSED,
    STRANGE_TOPICS,
    cut_in_its_middle,
    refused,
    small_recording,
    sqlite_bag,
    wide,
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


def _fuzzed_bag() -> tuple[bytes, str]:
    """The ``.db3`` file and ``metadata.yaml`` text of a small valid ROS 2 bag."""
    with tempfile.TemporaryDirectory() as folder:
        bag = sqlite_bag(Path(folder) / "bag")
        return (bag / "bag.db3").read_bytes(), (bag / "metadata.yaml").read_text()


BAG_DB3, BAG_METADATA = _fuzzed_bag()
SHARED_TYPES = MessageTypes()
"""The bus's types for the examples below (each learns types of names of its own)."""
EXAMPLES = itertools.count()

nesting = st.tuples(st.integers(1, 120), st.sampled_from(["[", "{a: ", "- ", "{a: ["]))
edit = st.tuples(st.integers(0, len(BAG_METADATA)), st.integers(0, 40),
                 st.text(alphabet="[]{}&*:,-'\"\n\t #!%@|>?~0123456789abc", max_size=12))
listing = st.tuples(st.sampled_from([0, 1, 2, 7, MAX_BAG_FILES, MAX_BAG_FILES + 1]),
                    st.integers(0, 3), st.sampled_from([0, 1, 2, 7, MAX_BAG_TOPICS + 1]))


def _nested(depth: int, opening: str) -> str:
    """A YAML document nesting ``depth`` collections opened with ``opening``."""
    if opening == "- ":
        return "".join("  " * level + "-\n" for level in range(depth)) + "  " * depth + "- 1\n"
    closing = "".join({"[": "]", "{": "}"}[char] for char in reversed(opening) if char in "[{")
    return opening * depth + "1" + closing * depth


def _edited(edits: list[tuple[int, int, str]]) -> str:
    """``BAG_METADATA`` with each (where, how many characters removed, what inserted) made."""
    text = BAG_METADATA
    for where, removed, inserted in edits:
        where = min(where, len(text))
        text = text[:where] + inserted + text[where + removed:]
    return text


def _listed(files: int, present: int, topics: int) -> str:
    """``BAG_METADATA`` listing ``files`` files (the first ``present`` the bag's own) and
    ``topics`` topics."""
    information = yaml.safe_load(BAG_METADATA)
    bag = information["rosbag2_bagfile_information"]
    bag["relative_file_paths"] = [("bag.db3" if number < present else f"gone_{number}.db3")
                                  for number in range(files)]
    bag["topics_with_message_count"] = bag["topics_with_message_count"][:1] * topics
    return str(yaml.safe_dump(information))


@settings(max_examples=150, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(shape=st.one_of(nesting.map(lambda shape: _nested(*shape)),
                       st.lists(edit, min_size=1, max_size=5).map(_edited),
                       listing.map(lambda shape: _listed(*shape))))
def test_a_hostile_bag_metadata_raises_nothing_but_a_one_line_recording_error(
        tmp_path: Path, shape: str) -> None:
    folder = tmp_path / "bag"
    folder.mkdir(exist_ok=True)
    (folder / "bag.db3").write_bytes(BAG_DB3)
    (folder / "metadata.yaml").write_text(shape)
    try:
        recording = open_recording(folder, SHARED_TYPES)
    except RecordingError as exc:
        assert str(exc).startswith(f"{folder}") and "\n" not in str(exc)
        assert len(str(exc)) < 500
        return
    try:
        played = list(recording.messages())  # 3 from each time the file is listed
        assert {item.topic for item in played} <= {"/chatter"}
        assert len(played) <= 3 * max(shape.count("bag.db3"), 1)
    finally:
        recording.close()


@settings(max_examples=80, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(fields=st.lists(st.integers(0, 12), min_size=1, max_size=4),
       uses=st.lists(st.integers(0, 3), min_size=0, max_size=12),
       chunk_size=st.sampled_from([64, 300, 1 << 20]))
def test_channels_and_schemas_around_their_bounds_are_refused_or_read_right(
        tmp_path: Path, fields: list[int], uses: list[int], chunk_size: int) -> None:
    """Schemas of ``fields`` fields each, a channel of ``uses[i]``'s schema each, under bounds
    of 8 channels and 8 fields a schema."""
    path, example = tmp_path / "run.mcap", next(EXAMPLES)
    with open(path, "wb") as stream:
        writer = Writer(stream, chunk_size=chunk_size)
        writer.start(profile="ros2", library="test")
        schemas = [writer.register_schema(f"their_msgs/msg/T{example}x{number}", "ros2msg",
                                          wide(count).encode() or b"int32 x\n")
                   for number, count in enumerate(fields)]
        for number, use in enumerate(uses):
            schema = use % len(schemas)
            channel = writer.register_channel(f"/t{number}", "cdr", schemas[schema])
            size = 4 * max(fields[schema], 1)
            writer.add_message(channel, 1_000 + number, b"\x00\x01\x00\x00" + bytes(size), 1)
        writer.finish()
    with mock.patch.object(scan_module, "MAX_CHANNELS", 8), \
            mock.patch.object(recorded, "MAX_SCHEMA_FIELDS", 8):
        try:
            recording = open_recording(path, SHARED_TYPES)
        except RecordingError as exc:
            assert len(uses) > 8 or not uses, exc
            assert str(exc).startswith(f"{path}: ") and "\n" not in str(exc)
            return
    try:
        assert len(uses) <= 8
        wide_ones = {f"/t{number}" for number, use in enumerate(uses)
                     if fields[use % len(fields)] > 8}
        assert set(recording.skipped) == wide_ones
        assert all("the most one may declare" in why for why in recording.skipped.values())
        played = [played.topic for played in recording.messages()]
        assert played == [f"/t{n}" for n in range(len(uses)) if f"/t{n}" not in wide_ones]
    finally:
        recording.close()
