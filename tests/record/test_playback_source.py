"""Opening recordings to play: a cut file plays its whole part and says where it was cut; an
empty or foreign file is refused naming it; unknown schemas are learnt from the file or the
topic is skipped and named; ROS 1 and ROS 2 bags play, ROS 1 messages converted to ROS 2."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from mcap.writer import Writer
from rosbags.rosbag1 import Writer as Ros1Writer
from rosbags.rosbag2 import Writer as Ros2Writer
from rosbags.typesys import Stores, get_typestore

from cyborg.bus import MessageTypes
from cyborg.bus.msgs.std_msgs.msg import String
from cyborg.record.playback_source import RecordingError, open_recording
from cyborg.record.scan import scan
from tests.record.playing import CHATTER, record_run

STRING = "std_msgs/msg/String"


@pytest.fixture(scope="module")
def run_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("run") / "run.mcap"
    record_run(path)
    return path


def test_a_whole_recording_lists_its_topics_latched_ones_and_plays_in_time_order(
        run_file: Path) -> None:
    recording = open_recording(run_file, MessageTypes())
    try:
        assert recording.cut is None and not recording.skipped
        assert {name: (t.type_name, t.latched, t.count) for name, t in recording.topics.items()
                } == {"/map": (STRING, True, 1), "/chatter": (STRING, False, CHATTER)}
        played = list(recording.messages())
        assert [p.log_time for p in played] == sorted(p.log_time for p in played)
        assert played[0].log_time == recording.start_ns and played[-1].log_time == recording.end_ns
        types = MessageTypes()
        assert [types.deserialize(p.data, STRING).data for p in played if p.topic == "/chatter"
                ] == [f"message {n}" for n in range(CHATTER)]
        assert [p.topic for p in recording.latched_before(recording.end_ns)] == ["/map"]
        assert recording.latched_before(recording.start_ns) == []
    finally:
        recording.close()


def test_a_cut_file_plays_what_it_can_and_says_where_it_was_cut(run_file: Path,
                                                                tmp_path: Path) -> None:
    data, found = run_file.read_bytes(), scan(run_file)
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(data[:found.end + 3])  # its Data End record cut short, no summary
    recording, whole = open_recording(cut, MessageTypes()), open_recording(run_file,
                                                                           MessageTypes())
    try:
        assert recording.cut == f"a record cut short at byte {found.end}"
        assert list(recording.messages()) == list(whole.messages())
    finally:
        recording.close()
        whole.close()
    cut.write_bytes(data[:found.chunks[0].offset + 20])  # inside its first chunk
    with pytest.raises(RecordingError, match=f"{cut}: holds no messages \\(cut: a record "):
        open_recording(cut, MessageTypes())


@pytest.mark.parametrize(("content", "said"), [
    (b"", "empty"),
    (b"just some notes\nabout a run\n", "a text file"),
    (b"#ROSBAG V2.0\n" + bytes(100), "a ROS 1 bag"),
    (b"SQLite format 3\x00" + bytes(100), "SQLite"),
])
def test_an_empty_or_foreign_file_is_refused_naming_it_and_what_it_is(
        tmp_path: Path, content: bytes, said: str) -> None:
    path = tmp_path / "run.mcap"
    path.write_bytes(content)
    with pytest.raises(RecordingError, match=said) as raised:
        open_recording(path, MessageTypes())
    assert str(path) in str(raised.value)


def test_a_missing_file_and_a_bad_bag_are_refused_naming_them(tmp_path: Path) -> None:
    with pytest.raises(RecordingError, match="no such file"):
        open_recording(tmp_path / "nothing.mcap", MessageTypes())
    fake = tmp_path / "robot.bag"
    fake.write_text("not a bag")
    with pytest.raises(RecordingError, match=f"{fake}: not a ROS 1 bag"):
        open_recording(fake, MessageTypes())
    with pytest.raises(RecordingError, match=r"without metadata\.yaml"):
        open_recording(tmp_path, MessageTypes())


def test_unknown_schemas_are_learnt_from_the_file_or_skipped_and_named(tmp_path: Path) -> None:
    path = tmp_path / "foreign.mcap"
    thing = "float64 speed\nstd_msgs/Header header\n" + "=" * 80 + \
        "\nMSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id\n" + \
        "=" * 80 + "\nMSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n"
    types = MessageTypes()
    with open(path, "wb") as stream:
        writer = Writer(stream)
        writer.start(profile="ros2", library="test")
        learnt = writer.register_schema("their_msgs/msg/Thing", "ros2msg", thing.encode())
        broken = writer.register_schema("their_msgs/msg/Broken", "ros2msg", b"no such type x\n")
        json_schema = writer.register_schema("Pose", "jsonschema", b"{}")
        channels = {
            "/thing": writer.register_channel("/thing", "cdr", learnt),
            "/broken": writer.register_channel("/broken", "cdr", broken),
            "/json": writer.register_channel("/json", "json", json_schema),
            "/text": writer.register_channel("/text", "cdr", writer.register_schema(
                STRING, "ros2msg", b"string data\n")),
        }
        text = bytes(types.serialize(String(data="hello"), STRING))
        for topic, channel in channels.items():
            writer.add_message(channel, 1_000, text if topic == "/text" else b"\x00\x01\x00\x00",
                               1_000)
        writer.finish()
    recording = open_recording(path, types)
    try:
        assert set(recording.topics) == {"/thing", "/text"}
        assert set(recording.skipped) == {"/broken", "/json"}
        assert "not cdr" in recording.skipped["/json"]
        assert "their_msgs/msg/Broken" in recording.skipped["/broken"]
        assert "their_msgs/msg/Thing" in types
    finally:
        recording.close()


def ros_messages(typestore: object) -> tuple[object, object]:
    store: object = typestore
    string = store.types[STRING](data="hello")  # type: ignore[attr-defined]
    header_type = store.types["std_msgs/msg/Header"]  # type: ignore[attr-defined]
    header_fields = {"stamp": store.types["builtin_interfaces/msg/Time"](  # type: ignore[attr-defined]
        sec=5, nanosec=7), "frame_id": "map"}
    if "seq" in header_type.__dataclass_fields__:
        header_fields["seq"] = 3
    pose = store.types["geometry_msgs/msg/PoseStamped"](  # type: ignore[attr-defined]
        header=header_type(**header_fields),
        pose=store.types["geometry_msgs/msg/Pose"](  # type: ignore[attr-defined]
            position=store.types["geometry_msgs/msg/Point"](x=1.0, y=2.0, z=0.0),  # type: ignore[attr-defined]
            orientation=store.types["geometry_msgs/msg/Quaternion"](  # type: ignore[attr-defined]
                x=0.0, y=0.0, z=0.0, w=1.0)))
    return string, pose


def test_a_ros1_bag_plays_its_messages_converted_to_ros2_latched_ones_latched(
        tmp_path: Path) -> None:
    store = get_typestore(Stores.ROS1_NOETIC)
    string, pose = ros_messages(store)
    path = tmp_path / "robot.bag"
    with Ros1Writer(path) as writer:
        chatter = writer.add_connection("/chatter", STRING, typestore=store, latching=1)
        poses = writer.add_connection("/pose", "geometry_msgs/msg/PoseStamped", typestore=store)
        writer.write(chatter, 1_000_000_000, store.serialize_ros1(string, STRING))
        writer.write(poses, 2_000_000_000, store.serialize_ros1(
            pose, "geometry_msgs/msg/PoseStamped"))
    types = MessageTypes()
    recording = open_recording(path, types)
    try:
        assert {n: t.latched for n, t in recording.topics.items()} == {"/chatter": True,
                                                                        "/pose": False}
        played = list(recording.messages())
        assert [p.topic for p in played] == ["/chatter", "/pose"]
        assert types.deserialize(played[0].data, STRING).data == "hello"
        got = types.deserialize(played[1].data, "geometry_msgs/msg/PoseStamped")
        assert (got.header.frame_id, got.header.stamp.sec, got.pose.position.y) == ("map", 5, 2.0)
        assert recording.duration == pytest.approx(1.0)
        assert [p.topic for p in recording.latched_before(2_000_000_000)] == ["/chatter"]
    finally:
        recording.close()


def test_a_ros2_bag_plays_its_cdr_as_it_is(tmp_path: Path) -> None:
    store = get_typestore(Stores.ROS2_HUMBLE)
    string, pose = ros_messages(store)
    path = tmp_path / "bag"
    with Ros2Writer(path, version=9) as writer:
        chatter = writer.add_connection("/chatter", STRING, typestore=store)
        poses = writer.add_connection("/pose", "geometry_msgs/msg/PoseStamped", typestore=store)
        data = [bytes(store.serialize_cdr(string, STRING)),
                bytes(store.serialize_cdr(pose, "geometry_msgs/msg/PoseStamped"))]
        writer.write(chatter, 10, data[0])
        writer.write(poses, 20, data[1])
    recording = open_recording(path, MessageTypes())
    try:
        assert [(p.topic, p.data) for p in recording.messages()] == [("/chatter", data[0]),
                                                                      ("/pose", data[1])]
        assert not any(t.latched for t in recording.topics.values())
    finally:
        recording.close()
    assert np.isclose(recording.duration, 10e-9)


def test_a_file_written_without_chunks_plays_every_message_in_time_order(tmp_path: Path) -> None:
    path = tmp_path / "unchunked.mcap"
    types = MessageTypes()
    with open(path, "wb") as stream:
        writer = Writer(stream, use_chunking=False)
        writer.start(profile="ros2", library="test")
        schema = writer.register_schema(STRING, "ros2msg", b"string data\n")
        chatter = writer.register_channel("/chatter", "cdr", schema)
        latched = writer.register_channel("/map", "cdr", schema, {
            "offered_qos_profiles": "- durability: transient_local\n"})
        for number in (3, 1, 2):  # out of order, as several writers' messages may be
            writer.add_message(chatter, number * 1000, bytes(types.serialize(
                String(data=f"message {number}"), STRING)), number * 1000)
        writer.add_message(latched, 1500, bytes(types.serialize(String(data="map"), STRING)),
                           1500)
        writer.finish()
    recording = open_recording(path, types)
    try:
        played = list(recording.messages())
        assert [(p.topic, p.log_time) for p in played] == [
            ("/chatter", 1000), ("/map", 1500), ("/chatter", 2000), ("/chatter", 3000)]
        assert types.deserialize(played[-1].data, STRING).data == "message 3"
        assert [p.log_time for p in recording.messages(2000)] == [2000, 3000]
        assert [(p.topic, p.log_time) for p in recording.latched_before(2500)] == [("/map", 1500)]
    finally:
        recording.close()
