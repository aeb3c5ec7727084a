"""MCAP files built to hold a reader up: schemas of thousands of fields or a megabyte, tens of
thousands of channels or schemas, megabytes of definitions. ``play``'s and ``report``'s reader
and ``--recover`` refuse each in one line naming the file and the byte where the record lies,
or skip the topic naming its type and the bound; what is within the bounds is read right."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from mcap.data_stream import RecordBuilder
from mcap.records import Channel, Chunk, DataEnd, Header, Message, Schema
from mcap.writer import Writer

from cyborg.bus import MessageTypes
from cyborg.record import recorded, scan
from cyborg.record.playback_source import RecordingError, open_recording
from cyborg.record.recorded import MAX_SCHEMA_BYTES, MAX_SCHEMA_FIELDS
from cyborg.record.recover import NotRecoverableError, recover
from cyborg.record.scan import MAGIC
from cyborg.report.recording import read_recording
from tests.record.bad_recordings import STRING, many_channels, small_recording, wide


def with_schemas(path: Path, schemas: dict[str, str], *, channels_each: int = 1) -> Path:
    """``small_recording`` with ``channels_each`` topics of each type in ``schemas`` (name to
    definition of int32 fields), one message of zeros on each."""
    def extra(writer: Writer) -> None:
        for type_name, text in schemas.items():
            schema = writer.register_schema(type_name, "ros2msg", text.encode())
            for number in range(channels_each):
                channel = writer.register_channel(f"/{type_name.rsplit('/', 1)[-1]}{number}",
                                                  "cdr", schema)
                data = b"\x00\x01\x00\x00" + bytes(4 * text.count("int32 "))  # zeros
                writer.add_message(channel, 1_000_000_000, data, 1_000_000_000)
    return small_recording(path, extra=extra)


def skipped(path: Path) -> dict[str, str]:
    """The topics ``path`` does not play, with why; every other topic must play."""
    recording = open_recording(path, MessageTypes())
    try:
        assert "/chatter" in recording.topics
        return recording.skipped
    finally:
        recording.close()


def test_a_schema_of_more_fields_than_the_bound_is_skipped_naming_it_and_the_rest_plays(
        tmp_path: Path) -> None:
    path = with_schemas(tmp_path / "run.mcap", {
        "their_msgs/msg/Wide": wide(40_000), "their_msgs/msg/Edge": wide(MAX_SCHEMA_FIELDS),
        "their_msgs/msg/Over": wide(MAX_SCHEMA_FIELDS + 1),
        "their_msgs/msg/Said": wide(3, comments=20_000)})
    assert skipped(path) == {
        topic: (f"their_msgs/msg/{name}: a definition of more than {MAX_SCHEMA_FIELDS:,} "
                "fields, the most one may declare (its constants and the types it uses counted)")
        for topic, name in (("/Wide0", "Wide"), ("/Over0", "Over"))}
    report = read_recording(path, lambda _topic, _type: True)
    edge = report.stamped("/Edge0")[0].message
    assert edge.f0 == 0 and edge.f999 == 0 and len(report.stamped("/Said0")) == 1
    assert set(report.skipped) == {"/Wide0", "/Over0"}


def test_a_schema_of_more_bytes_than_the_bound_is_skipped(tmp_path: Path) -> None:
    path = with_schemas(tmp_path / "run.mcap", {
        "their_msgs/msg/Long": "# " + "x" * MAX_SCHEMA_BYTES + "\nint32 a\n"})
    assert skipped(path) == {"/Long0": (
        f"their_msgs/msg/Long: a definition of {MAX_SCHEMA_BYTES + 11:,} characters, more "
        f"than the {MAX_SCHEMA_BYTES // 2**20} MiB one may hold")}


def test_the_fields_read_for_one_recording_are_bounded_and_each_schema_is_read_once(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(recorded, "MAX_LEARNED_FIELDS", 35)  # A, Bad (read once) and C
    path = with_schemas(tmp_path / "run.mcap", {
        "their_msgs/msg/A": wide(10), "their_msgs/msg/Bad": wide(9) + "their_msgs/Nowhere x\n",
        "their_msgs/msg/C": wide(10), "their_msgs/msg/D": wide(10)}, channels_each=3)
    said = skipped(path)
    assert set(said) == {f"/{name}{number}" for name in ("Bad", "D") for number in range(3)}
    assert all("their_msgs/msg/Nowhere, defined nowhere" in said[f"/Bad{n}"] for n in range(3))
    assert all(said[f"/D{n}"] == "their_msgs/msg/D: its definition's 10 fields would pass the "
               "35 read for one recording" for n in range(3))


def _refused_alike(path: Path, said: str, tmp_path: Path) -> None:
    """``path`` is refused by play's and report's reader and by --recover, saying ``said``."""
    with pytest.raises(RecordingError) as raised:
        open_recording(path, MessageTypes())
    assert str(raised.value).startswith(f"{path}: ") and said in str(raised.value)
    with pytest.raises(RecordingError, match=re.escape(said)):
        read_recording(path, lambda _topic, _type: True)
    with pytest.raises(NotRecoverableError, match=re.escape(said)):
        recover(path, tmp_path / "fixed.mcap")
    assert not (tmp_path / "fixed.mcap").exists()


def test_channels_past_the_bound_are_refused_and_up_to_it_read_right(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(scan, "MAX_CHANNELS", 40)
    over = many_channels(tmp_path / "over.mcap", 41, chunk_size=300)
    _refused_alike(over, "more than the 40 channels a recording may define (channel 41 in the "
                         "chunk at byte ", tmp_path)
    path = tmp_path / "edge.mcap"
    with open(path, "wb") as stream:  # 40 channels in many chunks, messages out of order
        writer = Writer(stream, chunk_size=300)
        writer.start(profile="ros2", library="test")
        schema = writer.register_schema(STRING, "ros2msg", b"string data\n")
        for number in range(40):
            channel = writer.register_channel(f"/t{number}", "cdr", schema)
            for time in (5_000 - number, 9_000 + number):
                writer.add_message(channel, time, b"\x00\x01\x00\x00\x01\x00\x00\x00\x00", time)
        writer.finish()
    report = read_recording(path, lambda _topic, _type: False)
    assert (report.start, report.end, report.message_count) == (4_961, 9_039, 80)
    assert all(topic.count == 2 for topic in report.topics.values()) and len(report.topics) == 40
    recovery = recover(path, tmp_path / "fixed.mcap")
    assert (recovery.messages, recovery.topics, recovery.start_ns) == (80, 40, 4_961)


def test_schemas_past_the_bound_are_refused(tmp_path: Path,
                                            monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(scan, "MAX_SCHEMAS", 3)
    path = with_schemas(tmp_path / "run.mcap", {f"their_msgs/msg/T{n}": wide(1) for n in range(3)})
    _refused_alike(path, "more than the 3 schemas a recording may define (schema 4 ", tmp_path)


def raw_recording(path: Path, chunks: list[list[Schema | Channel | Message]]) -> Path:
    """An MCAP file of uncompressed chunks holding ``chunks``' records as given (a schema or
    channel may come again), ended by a Data End record."""
    builder = RecordBuilder()
    builder.write(MAGIC)
    Header(profile="ros2", library="test").write(builder)
    for records in chunks:
        inner = RecordBuilder()
        for record in records:
            record.write(inner)
        data = inner.end()
        Chunk(compression="", data=data, message_start_time=0, message_end_time=0,
              uncompressed_crc=0, uncompressed_size=len(data)).write(builder)
    DataEnd(0).write(builder)
    path.write_bytes(builder.end())
    return path


def test_schema_and_channel_bytes_past_the_bound_are_refused_but_a_repeated_one_is_not_added(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(scan, "MAX_DEFINITION_BYTES", 20_000)
    text = wide(1, comments=1_000).encode()  # 12 KB

    def chunk(schema_id: int, time: int) -> list[Schema | Channel | Message]:
        return [Schema(id=schema_id, name="their_msgs/msg/Big", encoding="ros2msg", data=text),
                Channel(id=1, schema_id=schema_id, topic="/big", message_encoding="cdr",
                        metadata={}),
                Message(channel_id=1, sequence=0, log_time=time, publish_time=time,
                        data=b"\x00\x01\x00\x00\x05\x00\x00\x00")]
    same = raw_recording(tmp_path / "same.mcap", [chunk(7, time) for time in range(5)])
    recording = open_recording(same, MessageTypes())
    try:
        assert [played.log_time for played in recording.messages()] == list(range(5))
    finally:
        recording.close()
    apart = raw_recording(tmp_path / "apart.mcap", [chunk(7, 0), chunk(8, 1)])
    _refused_alike(apart, "more than 20,000 bytes of schema and channel records (the schema "
                          "record in the chunk at byte ", tmp_path)
