"""Message types, CDR and RIHS01 type hashes (rmw_zenoh.md §10-11)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from cyborg.bus import InterfaceError, MessageTypes
from cyborg.bus.message_types import read_interfaces


@pytest.fixture(scope="module")
def types() -> MessageTypes:
    return MessageTypes()


# Published vectors, checked against ROS 2 (rmw_zenoh.md §10.1).
VERIFIED = {
    "std_msgs/msg/String": "df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18",
    "example_interfaces/srv/AddTwoInts":
        "e118de6bf5eeb66a2491b5bda11202e7b68f198d6f67922cf30364858239c81a",
    "sensor_msgs/msg/Image": "d31d41a9a4c4bc8eae9be757b0beed306564f7526c88ea6a4588fb9582527d47",
    "std_srvs/srv/SetBool": "abe9e4bb6b41b40e6789712c00ec8871923e089af3f667a79992a428cff2da0a",
    "std_srvs/srv/SetBool_Request":
        "c62fbb99d94e1b25e8ef9e109f9581956bb1b3361a45a4e5810c36a90d29932e",
    "service_msgs/msg/ServiceEventInfo":
        "41bcbbe07a75c9b52bc96bfd5c24d7f0fc0a08c0cb7921b3373c5732345a6f45",
}


@pytest.mark.parametrize(("type_name", "digest"), VERIFIED.items())
def test_published_rihs01_vectors(types: MessageTypes, type_name: str, digest: str) -> None:
    assert types.hash(type_name) == f"RIHS01_{digest}"


@pytest.mark.parametrize(("type_name", "head", "tail"), [
    ("std_msgs/msg/Header", "f49fb3ae", "6a01"),
    ("geometry_msgs/msg/Twist", "9c45bf16", "8d2a"),
    ("sensor_msgs/msg/CompressedImage", "15640771", "371a"),
    ("sensor_msgs/msg/CameraInfo", "b3dfd68f", "e275"),
    ("nav_msgs/msg/Odometry", "3cc97dc7", "ec6e0"),
])
def test_recorded_hash_prefixes(types: MessageTypes, type_name: str, head: str,
                                tail: str) -> None:
    digest = types.hash(type_name).removeprefix("RIHS01_")
    assert digest.startswith(head) and digest.endswith(tail)


def _package(tmp_path: Path, files: dict[str, str]) -> Path:
    for relative, text in files.items():
        path = tmp_path / relative
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)
    return tmp_path


def test_char_hashes_as_uint8(tmp_path: Path) -> None:
    root = _package(tmp_path, {"demo_msgs/msg/WithChar.msg": "char c\nchar[4] word\n",
                               "demo_msgs/msg/WithUint8.msg": "uint8 c\nuint8[4] word\n"})
    types = MessageTypes([root])
    with_char = types.hash("demo_msgs/msg/WithChar")
    assert [f["type_id"] for _, f in types.fields("demo_msgs/msg/WithChar")] == [3, 51]
    # Same fields as uint8 except the type name; rosbags' own hash (char -> 13) differs.
    assert with_char != types.store.hash_rihs01("demo_msgs/msg/WithChar")
    assert types.fields("demo_msgs/msg/WithChar") == types.fields("demo_msgs/msg/WithUint8")


def test_bounded_strings_sequences_and_arrays(tmp_path: Path) -> None:
    root = _package(tmp_path, {"demo_msgs/msg/Bounds.msg":
                               "string<=8 name\nstring<=4[<=3] tags\nint32[3] fixed\n"
                               "float64[<=5] bounded\nbyte[] raw\nbool flag\n"})
    types = MessageTypes([root])
    fields = dict(types.fields("demo_msgs/msg/Bounds"))
    assert (fields["name"]["type_id"], fields["name"]["string_capacity"]) == (21, 8)
    assert (fields["tags"]["type_id"], fields["tags"]["capacity"],
            fields["tags"]["string_capacity"]) == (21 + 96, 3, 4)
    assert (fields["fixed"]["type_id"], fields["fixed"]["capacity"]) == (6 + 48, 3)
    assert (fields["bounded"]["type_id"], fields["bounded"]["capacity"]) == (11 + 96, 5)
    assert (fields["raw"]["type_id"], fields["raw"]["capacity"]) == (16 + 144, 0)
    assert fields["flag"]["type_id"] == 15


def test_nested_packages_and_relative_names(tmp_path: Path) -> None:
    root = _package(tmp_path, {
        "demo_msgs/msg/Spot.msg": "string name\ngeometry_msgs/Pose2D pose\n",
        "demo_msgs/msg/Spots.msg": "std_msgs/Header header\nSpot[] spots\n",
        "demo_msgs/srv/Find.srv": "string name\n---\nSpot spot\n",
    })
    types = MessageTypes([root])
    spots = dict(types.fields("demo_msgs/msg/Spots"))
    assert spots["spots"]["nested_type_name"] == "demo_msgs/msg/Spot"
    response = dict(types.fields("demo_msgs/srv/Find_Response"))
    assert response["spot"]["nested_type_name"] == "demo_msgs/msg/Spot"
    assert types.hash("demo_msgs/srv/Find").startswith("RIHS01_")
    # The hash covers nested types: changing Spot changes Spots' hash.
    other = _package(tmp_path / "b", {
        "demo_msgs/msg/Spot.msg": "string name\ngeometry_msgs/Pose pose\n",
        "demo_msgs/msg/Spots.msg": "std_msgs/Header header\nSpot[] spots\n"})
    assert MessageTypes([other]).hash("demo_msgs/msg/Spots") != types.hash("demo_msgs/msg/Spots")


def test_cyborg_msgs_are_registered(types: MessageTypes) -> None:
    for name in ("BehaviorTree", "BehaviorTreeNodes", "BehaviorTreeStatus", "GoalWithHeading",
                 "Prediction", "Predictions", "BatteryStatus", "BehaviorTreeHooks"):
        assert f"cyborg_msgs/msg/{name}" in types
    for name in ("AvailableGoals", "ClosestGoal", "DistanceToGoal", "MakePlan", "LoadMapFile",
                 "ControlNode", "ReloadTree", "GetBlackboard", "SetPose"):
        assert f"cyborg_msgs/srv/{name}" in types.services
        assert f"cyborg_msgs/srv/{name}_Request" in types
        assert f"cyborg_msgs/srv/{name}_Event" in types
    assert "cyborg_msgs/action/MoveToGoal" in types.actions
    for part in ("Goal", "Result", "Feedback", "FeedbackMessage", "SendGoal_Request",
                 "SendGoal_Response", "GetResult_Request", "GetResult_Response"):
        assert f"cyborg_msgs/action/MoveToGoal_{part}" in types
    fields = [name for name, _ in types.fields("cyborg_msgs/msg/GoalWithHeading")]
    assert fields == ["name", "comment", "position", "has_heading"]  # the 2018 fields first
    assert [n for n, _ in types.fields("cyborg_msgs/msg/Prediction")] == [
        "label", "confidence", "distance", "bounding_box"]


def test_cdr_round_trip_and_numpy_views(types: MessageTypes) -> None:
    status_cls = types.message_class("cyborg_msgs/msg/BehaviorTreeStatus")
    time_cls = types.message_class("builtin_interfaces/msg/Time")
    message = status_cls(stamp=time_cls(sec=12, nanosec=5), tick=42, duration=0.001, status=3,
                         visited_ids=["a", "b/c"],
                         visited_statuses=np.array([1, 3], dtype=np.uint8),
                         visited_durations=np.array([1e-5, 2e-6], dtype=np.float32),
                         active_ids=["b/c"], halted_ids=[], mode="normal")
    raw = bytes(types.serialize(message, "cyborg_msgs/msg/BehaviorTreeStatus"))
    back = types.deserialize(raw, "cyborg_msgs/msg/BehaviorTreeStatus")
    assert (back.tick, back.visited_ids, back.stamp.sec, back.mode) == (42, ["a", "b/c"], 12,
                                                                          "normal")
    assert back.visited_statuses.tolist() == [1, 3]
    image_cls = types.message_class("sensor_msgs/msg/Image")
    header_cls = types.message_class("std_msgs/msg/Header")
    pixels = np.arange(4 * 6 * 3, dtype=np.uint8)
    image = image_cls(header=header_cls(stamp=time_cls(sec=1, nanosec=0), frame_id="cam"),
                      height=4, width=6, encoding="bgr8", is_bigendian=0, step=18, data=pixels)
    buffer = bytearray(types.serialize(image, "sensor_msgs/msg/Image"))
    decoded = types.deserialize(buffer, "sensor_msgs/msg/Image")
    assert np.array_equal(decoded.data, pixels)
    assert np.shares_memory(decoded.data, np.frombuffer(buffer, dtype=np.uint8)), "a view"
    assert not decoded.data.flags.writeable, "receivers cannot corrupt a shared buffer"
    from_bytes = types.deserialize(bytes(buffer), "sensor_msgs/msg/Image")
    assert np.array_equal(from_bytes.data, pixels)


def test_empty_service_parts_get_the_placeholder_member(types: MessageTypes) -> None:
    assert [n for n, _ in types.fields("std_srvs/srv/Empty_Request")] == [
        "structure_needs_at_least_one_member"]
    request = types.message_class("std_srvs/srv/Empty_Request")(
        structure_needs_at_least_one_member=0)
    raw = bytes(types.serialize(request, "std_srvs/srv/Empty_Request"))
    assert raw == b"\x00\x01\x00\x00\x00"


def test_bad_interface_files_name_the_file(tmp_path: Path) -> None:
    root = _package(tmp_path, {"demo_msgs/srv/Broken.srv": "int32 a\n"})
    with pytest.raises(InterfaceError, match=r"Broken\.srv: a \.srv file has 2 part"):
        read_interfaces(root)
    wide = _package(tmp_path / "w", {"demo_msgs/msg/Wide.msg": "wstring text\n"})
    with pytest.raises(InterfaceError, match=r"Wide\.msg.*wstring is not supported"):
        MessageTypes([wide])
    garbage = _package(tmp_path / "g", {"demo_msgs/msg/Bad.msg": "int32 = = 3\n"})
    with pytest.raises(InterfaceError, match=r"Bad\.msg"):
        MessageTypes([garbage])


def test_unknown_type(types: MessageTypes) -> None:
    with pytest.raises(KeyError, match="unknown type 'nope/msg/Nope'"):
        types.hash("nope/msg/Nope")


def test_a_definition_from_a_recording_adds_its_types_and_keeps_the_bus_own() -> None:
    types = MessageTypes()
    header = types.store.types["std_msgs/msg/Header"]
    text = ("std_msgs/Header header\nfloat64[] speeds\n" + "=" * 80
            + "\nMSG: std_msgs/Header\nuint32 seq\nbuiltin_interfaces/Time stamp\n")
    assert types.add_definition("their_msgs/msg/Run", text) == ["their_msgs/msg/Run"]
    assert types.store.types["std_msgs/msg/Header"] is header  # not the recording's, with seq
    run = types.message_class("their_msgs/msg/Run")
    assert types.hash("their_msgs/msg/Run").startswith("RIHS01_")
    message = types.deserialize(types.serialize(run(header=header(
        stamp=types.message_class("builtin_interfaces/msg/Time")(sec=1, nanosec=2),
        frame_id="map"), speeds=np.array([0.5])), "their_msgs/msg/Run"), "their_msgs/msg/Run")
    assert message.header.frame_id == "map" and message.speeds.tolist() == [0.5]
    with pytest.raises(ValueError, match="field pose of their_msgs/msg/Bad is of type "
                                         "their_msgs/msg/Missing, defined nowhere"):
        types.add_definition("their_msgs/msg/Bad", "their_msgs/Missing pose\n")
    assert "their_msgs/msg/Bad" not in types
    with pytest.raises(ValueError, match="their_msgs/msg/Worse: its definition cannot be read"):
        types.add_definition("their_msgs/msg/Worse", "float64 = = =\n")
