"""rosbag2's own description of a recording: every file's ``rosbag2`` metadata record, and a
split recording's ``metadata.yaml``, agree with the files' MCAP statistics, and rosbags opens
the split folder as one bag."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml
from mcap.reader import make_reader
from rosbags.highlevel import AnyReader

from cyborg.bus import MessageTypes
from cyborg.bus.msgs.geometry_msgs.msg import Pose2D
from cyborg.bus.msgs.std_msgs.msg import String
from cyborg.record.playback_source import open_recording
from cyborg.record.split import RecordingFiles, SplitPolicy, parse_size

TYPES = MessageTypes()
STRING, POSE = "std_msgs/msg/String", "geometry_msgs/msg/Pose2D"
BASE = 1_700_000_000_000_000_000
LATCHED_QOS = "1:1:1,1:,:,:,,"


def write(files: RecordingFiles, count: int) -> list[bytes]:
    """``count`` strings of 1 kB on /log and a pose every tenth message; what was written."""
    files.add_metadata("cyborg", {"cyborg_version": "1.2.3", "map": "campus.map"})
    files.add_topic("/log", STRING, [])
    files.add_topic("/pose", POSE, [LATCHED_QOS])
    written = []
    for number in range(count):
        data = bytes(TYPES.serialize(String(data=f"{number:05d}" + "z" * 1000), STRING))
        files.write("/log", BASE + number * 1_000_000, BASE + number * 1_000_000, data)
        written.append(data)
        if number % 10 == 0:
            pose = bytes(TYPES.serialize(Pose2D(x=float(number), y=0.0, theta=0.0), POSE))
            files.write("/pose", BASE + number * 1_000_000 + 1, BASE, pose)
            written.append(pose)
    files.close()
    return written


def file_facts(path: Path) -> tuple[dict[str, Any], dict[str, Any]]:
    """What the file's statistics and channels say, and its rosbag2 record's YAML, parsed."""
    with open(path, "rb") as stream:
        reader = make_reader(stream)
        summary = reader.get_summary()
        assert summary is not None and summary.statistics is not None
        records = [item for item in reader.iter_metadata() if item.name == "rosbag2"]
    assert len(records) == 1
    statistics = summary.statistics
    channels = summary.channels
    facts = {
        "start": statistics.message_start_time, "end": statistics.message_end_time,
        "count": statistics.message_count,
        "topics": {channels[channel].topic: count for channel, count
                   in statistics.channel_message_counts.items()},
        "types": {channel.topic: summary.schemas[channel.schema_id].name
                  for channel in channels.values()},
        "qos": {channel.topic: yaml.safe_load(channel.metadata["offered_qos_profiles"])
                for channel in channels.values()},
        "hash": {channel.topic: channel.metadata["topic_type_hash"]
                 for channel in channels.values()}}
    return facts, yaml.safe_load(records[0].metadata["serialized_metadata"])


def check_information(information: dict[str, Any], facts: dict[str, Any]) -> None:
    """``information`` (a rosbag2_bagfile_information) says what ``facts`` say."""
    assert information["version"] == 9 and information["storage_identifier"] == "mcap"
    assert information["starting_time"]["nanoseconds_since_epoch"] == facts["start"]
    assert information["duration"]["nanoseconds"] == facts["end"] - facts["start"]
    assert information["message_count"] == facts["count"]
    topics = {item["topic_metadata"]["name"]: item for item in
              information["topics_with_message_count"]}
    assert {name: item["message_count"] for name, item in topics.items()} == facts["topics"]
    for name, item in topics.items():
        metadata = item["topic_metadata"]
        assert metadata["type"] == facts["types"][name]
        assert metadata["serialization_format"] == "cdr"
        assert metadata["offered_qos_profiles"] == (facts["qos"][name] or [])
        assert metadata["type_description_hash"] == facts["hash"][name]
    assert information["custom_data"] == {"cyborg_version": "1.2.3", "map": "campus.map"}


def test_a_file_holds_a_rosbag2_record_that_matches_its_statistics(tmp_path: Path) -> None:
    path = tmp_path / "run.mcap"
    write(RecordingFiles(path, TYPES, "zstd"), 300)
    facts, record = file_facts(path)
    information = record["rosbag2_bagfile_information"]
    check_information(information, facts)
    assert information["relative_file_paths"] == ["run.mcap"]
    assert [item["message_count"] for item in information["files"]] == [facts["count"]]
    assert facts["topics"] == {"/log": 300, "/pose": 30}
    assert facts["qos"]["/pose"][0]["durability"] == "transient_local"


def test_a_split_folder_lists_every_file_and_rosbags_reads_it_as_one_bag(tmp_path: Path) -> None:
    files = RecordingFiles(tmp_path / "run.mcap", TYPES, "none",
                           SplitPolicy(size=parse_size("1MiB")))
    written = write(files, 2500)
    folder = tmp_path / "run"
    assert len(files.paths) == 3 and all(path.parent == folder for path in files.paths)
    information = yaml.safe_load((folder / "metadata.yaml").read_text())[
        "rosbag2_bagfile_information"]
    assert information["relative_file_paths"] == [path.name for path in files.paths]
    totals: dict[str, int] = {}
    for entry, path in zip(information["files"], files.paths, strict=True):
        facts, record = file_facts(path)
        check_information(record["rosbag2_bagfile_information"], facts)
        assert entry["path"] == path.name and entry["message_count"] == facts["count"]
        assert entry["starting_time"]["nanoseconds_since_epoch"] == facts["start"]
        assert entry["duration"]["nanoseconds"] == facts["end"] - facts["start"]
        for topic, count in facts["topics"].items():
            totals[topic] = totals.get(topic, 0) + count
    assert information["message_count"] == len(written) == sum(totals.values())
    assert {item["topic_metadata"]["name"]: item["message_count"]
            for item in information["topics_with_message_count"]} == totals
    assert information["starting_time"]["nanoseconds_since_epoch"] == BASE
    with AnyReader([folder]) as reader:
        assert reader.message_count == len(written)
        assert [bytes(raw) for _c, _t, raw in reader.messages()] == written
    played = open_recording(folder, MessageTypes())
    try:
        assert [p.data for p in played.messages()] == written
        assert played.topics["/pose"].latched
    finally:
        played.close()
