"""A recording read back by independent readers equals what was published on the bus."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from cyborg.bus import BusConfig, Context, Node, Publisher, Qos
from cyborg.bus.msgs.builtin_interfaces.msg import Time
from cyborg.bus.msgs.cyborg_msgs.msg import BehaviorTreeStatus
from cyborg.bus.msgs.geometry_msgs.msg import Pose2D
from cyborg.bus.msgs.sensor_msgs.msg import LaserScan
from cyborg.bus.msgs.std_msgs.msg import Header, String
from cyborg.record import layout
from cyborg.record.recorder import Recorder
from cyborg.record.selection import TopicSelection
from cyborg.record.split import RecordingFiles
from tests.bus.bus_peer import linked_contexts, until_subscribed, wait_for
from tests.record.readers import plain, raw_messages, read_mcap, read_rosbags

COUNT = 6


def scan(i: int) -> LaserScan:
    return LaserScan(header=Header(stamp=Time(sec=i, nanosec=250), frame_id="laser"),
                     angle_min=-1.5, angle_max=1.5, angle_increment=0.25, time_increment=0.0,
                     scan_time=0.125, range_min=0.0625, range_max=30.0,
                     ranges=np.arange(13, dtype=np.float32) * 0.5 + i,
                     intensities=np.zeros(0, dtype=np.float32))


def status(i: int) -> BehaviorTreeStatus:
    return BehaviorTreeStatus(stamp=Time(sec=100 + i, nanosec=0), tick=i + 1, duration=0.5,
                              status=3, visited_ids=["a", f"n{i}"],
                              visited_statuses=np.array([1, 3], dtype=np.uint8),
                              visited_durations=np.array([0.25, 0.5], dtype=np.float32),
                              active_ids=["root", f"n{i}"], halted_ids=[],
                              mode="")


MESSAGES: dict[str, tuple[type, Any]] = {
    "/robot/pose": (Pose2D, lambda i: Pose2D(x=i * 0.5, y=-1.0 * i, theta=0.25)),
    "/robot/scan": (LaserScan, scan),
    "/robot/log": (String, lambda i: String(data=f"message {i} äöü")),
    "/robot/bt/status": (BehaviorTreeStatus, status),
}


def record_published(path: Path, recording: Context, publishing: Context) -> Recorder:
    """Publishes MESSAGES from ``publishing`` (and a latched one) and records them."""
    talker = Node("talker", context=publishing)
    publishers: dict[str, Publisher[Any]] = {topic: talker.create_publisher(topic, kind)
                  for topic, (kind, _make) in MESSAGES.items()}
    latched = talker.create_publisher("/robot/latched", String, Qos.latched())
    latched.publish(String(data="published before the recording"))
    recorder = Recorder(Node("recorder", context=recording),
                        RecordingFiles(path, recording.types), TopicSelection.of())
    expected = {*MESSAGES, "/robot/latched"}
    assert wait_for(lambda: set(recorder.stats.topics) >= expected, 20), recorder.stats.topics
    if publishing is not recording:
        for topic in MESSAGES:
            until_subscribed(publishing, topic, 20)
    for i in range(COUNT):
        for topic, (_kind, make) in MESSAGES.items():
            publishers[topic].publish(make(i))
    total = COUNT * len(MESSAGES) + 1
    assert wait_for(lambda: recorder.stats.messages >= total, 20), recorder.stats
    recorder.close()
    return recorder


def expected_plain() -> dict[str, list[Any]]:
    found = {topic: [plain(make(i)) for i in range(COUNT)]
             for topic, (_kind, make) in MESSAGES.items()}
    found["/robot/latched"] = [{"data": "published before the recording"}]
    return found


@pytest.mark.parametrize("where", ["same process", "another session"])
def test_both_readers_read_back_every_message_as_published(tmp_path: Path, where: str) -> None:
    path = tmp_path / "run.mcap"
    if where == "same process":
        with Context(BusConfig.isolated()) as context:
            record_published(path, context, context)
    else:
        with linked_contexts() as (recording, publishing):
            record_published(path, recording, publishing)
    assert read_mcap(path) == expected_plain()
    assert read_rosbags(path) == expected_plain()


def test_payloads_are_the_bus_cdr_and_times_come_from_the_attachment(tmp_path: Path) -> None:
    path = tmp_path / "run.mcap"
    before = time.time_ns()
    with linked_contexts() as (recording, publishing):
        record_published(path, recording, publishing)
        types = publishing.types
    after = time.time_ns()
    by_topic: dict[str, list[tuple[int, int, bytes]]] = {}
    for topic, log_time, publish_time, data in raw_messages(path):
        by_topic.setdefault(topic, []).append((log_time, publish_time, data))
    for topic, (kind, make) in MESSAGES.items():
        sent = [bytes(types.serialize(make(i), types.type_name(kind))) for i in range(COUNT)]
        assert [data for _log, _pub, data in by_topic[topic]] == sent
        for log_time, publish_time, _data in by_topic[topic]:
            assert before <= publish_time <= log_time <= after


def test_the_file_has_the_ros2_profile_schemas_channels_and_a_full_summary(
        tmp_path: Path) -> None:
    from mcap.reader import make_reader
    path = tmp_path / "run.mcap"
    with Context(BusConfig.isolated()) as context:
        record_published(path, context, context)
        types = context.types
    with open(path, "rb") as stream:
        reader = make_reader(stream)
        header, summary = reader.get_header(), reader.get_summary()
        metadata = {item.name: item.metadata for item in reader.iter_metadata()}
    assert header.profile == layout.PROFILE
    assert summary is not None and summary.statistics is not None
    assert summary.statistics.message_count == COUNT * len(MESSAGES) + 1
    assert summary.chunk_indexes and all(index.message_index_offsets
                                         for index in summary.chunk_indexes)
    channels = {channel.topic: channel for channel in summary.channels.values()}
    scan_channel = channels["/robot/scan"]
    schema = summary.schemas[scan_channel.schema_id]
    assert (schema.name, schema.encoding) == ("sensor_msgs/msg/LaserScan", "ros2msg")
    assert schema.data.decode().splitlines()[0] == "std_msgs/Header header"
    assert "\n" + "=" * 80 + "\nMSG: std_msgs/Header\n" in schema.data.decode()
    assert scan_channel.message_encoding == "cdr"
    assert scan_channel.metadata["topic_type_hash"] == types.hash("sensor_msgs/msg/LaserScan")
    assert "reliability: reliable" in scan_channel.metadata["offered_qos_profiles"]
    latched = channels["/robot/latched"].metadata["offered_qos_profiles"]
    assert "durability: transient_local" in latched
    assert metadata["cyborg"]["cyborg_version"]
