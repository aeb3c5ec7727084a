"""Split recordings: run_0.mcap, run_1.mcap, ... each complete, no message lost or doubled;
sizes and durations are read with clear errors."""

from __future__ import annotations

from pathlib import Path

import pytest
from mcap.reader import make_reader

from cyborg.bus import MessageTypes
from cyborg.bus.msgs.std_msgs.msg import String
from cyborg.record.split import (
    RecordingFiles,
    SplitPolicy,
    parse_duration,
    parse_size,
    split_name,
)
from tests.record.readers import raw_messages

TYPES = MessageTypes()


def test_sizes_and_durations_are_read_in_the_usual_units() -> None:
    assert parse_size("1GiB") == 2**30
    assert parse_size("500MB") == 500_000_000
    assert parse_size("2 mib") == 2 * 2**20
    assert parse_duration("10m") == 600
    assert parse_duration("90s") == 90
    assert parse_duration("1.5h") == 5400
    assert parse_duration("30") == 30


@pytest.mark.parametrize(("parse", "text", "message"), [
    (parse_size, "big", "--split-size 'big': expected a size"),
    (parse_size, "10XB", "--split-size '10XB': expected a size"),
    (parse_size, "100kB", "--split-size '100kB': at least 1MiB"),
    (parse_duration, "soon", "--split-duration 'soon': expected a duration"),
    (parse_duration, "0s", "--split-duration '0s': must be more than 0"),
])
def test_bad_sizes_and_durations_name_the_option(parse: object, text: str,
                                                 message: str) -> None:
    with pytest.raises(ValueError, match=message.replace("(", r"\(")):
        parse(text)  # type: ignore[operator]


def test_split_files_are_named_as_rosbag2_names_them_in_a_bag_folder() -> None:
    assert split_name(Path("out/run.mcap"), 0) == Path("out/run/run_0.mcap")
    assert split_name(Path("run.mcap"), 12) == Path("run/run_12.mcap")
    assert split_name(Path("run"), 1) == Path("run/run_1.mcap")


def test_a_recording_split_by_size_loses_no_message_and_each_file_stands_alone(
        tmp_path: Path) -> None:
    files = RecordingFiles(tmp_path / "run.mcap", TYPES, "none",
                           SplitPolicy(size=parse_size("1MiB")))
    files.add_metadata("cyborg", {"map": "campus.map"})
    files.add_topic("/log", "std_msgs/msg/String", [])
    files.add_topic("/quiet", "std_msgs/msg/String", [])
    sent = []
    for i in range(3000):
        data = bytes(TYPES.serialize(String(data=f"{i:05d}" + "z" * 1000), "std_msgs/msg/String"))
        files.write("/log", 10**18 + i, 10**18 + i, data)
        sent.append(data)
    files.close()
    assert files.paths == [tmp_path / "run" / f"run_{i}.mcap" for i in range(len(files.paths))]
    assert len(files.paths) == 3
    assert not (tmp_path / "run.mcap").exists()
    assert sorted(p.name for p in (tmp_path / "run").iterdir()) == [
        "metadata.yaml", "run_0.mcap", "run_1.mcap", "run_2.mcap"]
    got = [data for path in files.paths for _t, _l, _p, data in raw_messages(path)]
    assert got == sent
    for path in files.paths:
        assert path.stat().st_size <= parse_size("1MiB") + 2 * 2**20 // 100
        with open(path, "rb") as stream:
            reader = make_reader(stream)
            summary = reader.get_summary()
            metadata = [(item.name, item.metadata) for item in reader.iter_metadata()]
        assert summary is not None
        assert {channel.topic for channel in summary.channels.values()} == {"/log", "/quiet"}
        assert metadata[0] == ("cyborg", {"map": "campus.map"})
        assert [name for name, _values in metadata] == ["cyborg", "rosbag2"]


def test_an_existing_file_is_never_overwritten(tmp_path: Path) -> None:
    (tmp_path / "run.mcap").write_text("keep me")
    with pytest.raises(FileExistsError, match=r"run\.mcap exists already"):
        RecordingFiles(tmp_path / "run.mcap", TYPES)
    (tmp_path / "parts").mkdir()
    (tmp_path / "parts" / "parts_0.mcap").write_text("keep me")
    with pytest.raises(FileExistsError, match=f"{tmp_path / 'parts'} exists already"):
        RecordingFiles(tmp_path / "parts.mcap", TYPES, policy=SplitPolicy(duration=60))
    assert (tmp_path / "parts" / "parts_0.mcap").read_text() == "keep me"
    assert (tmp_path / "run.mcap").read_text() == "keep me"
