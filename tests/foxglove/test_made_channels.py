"""What the server makes for Foxglove: a robot's map as grid and scene, its frame, tree ticks."""

from __future__ import annotations

import base64
import json
from typing import Any

import numpy as np
import pytest
from google.protobuf import descriptor_pb2, descriptor_pool, message_factory

from cyborg.bus import new_message
from cyborg.bus.msgs.builtin_interfaces.msg import Time
from cyborg.bus.msgs.cyborg_msgs.msg import BehaviorTree, BehaviorTreeStatus
from cyborg.bus.msgs.nav_msgs.msg import Odometry
from cyborg.interfaces import robot, tree_runner
from cyborg.nav.arnl_map import parse_map
from cyborg.nav.map_message import map_geometry
from tests.builders import N, tree_from
from tests.foxglove.conftest import Repeating, Served
from tests.small_maps import room_map

ROOM = room_map(['GoalWithHeading 2000 3000 90 "" ICON "charger view"',
                 'Goal 7000 1000 0 "" ICON "window"',
                 'ForbiddenArea 0 0 0 "" ICON "" 6000 4000 8000 5000'])


def decode_protobuf(channel: dict[str, Any], payload: bytes) -> Any:
    """A protobuf payload decoded by the schema the channel advertised (a FileDescriptorSet)."""
    assert channel["schemaEncoding"] == "protobuf"
    files = descriptor_pb2.FileDescriptorSet.FromString(base64.b64decode(channel["schema"]))
    pool = descriptor_pool.DescriptorPool()
    for file in files.file:
        pool.Add(file)
    message_class = message_factory.GetMessageClass(
        pool.FindMessageTypeByName(channel["schemaName"]))
    return message_class.FromString(payload)


def publish_robot(served: Served) -> None:
    node = served.publisher_node
    robot.POSE.publisher(node)  # a robot is found by its pose
    robot.MAP_GEOMETRY.publisher(node).publish(map_geometry(parse_map(ROOM, "room.map")))


def test_the_map_is_offered_as_an_occupancy_grid(served: Served) -> None:
    publish_robot(served)
    with served.client() as client:
        channel = client.channel("/cyborg/map")
        assert (channel["schemaName"], channel["encoding"]) == ("nav_msgs/msg/OccupancyGrid",
                                                                "cdr")
        assert "MSG: nav_msgs/MapMetaData" in channel["schema"]
        payload = client.payloads(client.subscribe("/cyborg/map"))[0]
    grid = served.context.types.deserialize(payload, "nav_msgs/msg/OccupancyGrid")
    info = grid.info
    assert grid.header.frame_id == "map"
    assert info.resolution == pytest.approx(0.05)  # the room's 2 cm, held to the finest cell
    cells = np.asarray(grid.data).reshape(info.height, info.width)

    def cell(x: float, y: float) -> int:
        column = int((x - info.origin.position.x) / info.resolution)
        row = int((y - info.origin.position.y) / info.resolution)
        return int(cells[row, column])
    assert cell(5.0, 1.0) == 100  # the dividing wall
    assert cell(2.0, 2.0) == 0  # open floor
    assert cell(7.0, 4.5) == 60  # inside the forbidden area
    assert cell(5.0, 3.0) == 0  # the door


def test_the_map_is_offered_as_scene_lines_and_named_goals(served: Served) -> None:
    publish_robot(served)
    with served.client() as client:
        channel = client.channel("/cyborg/map_scene")
        assert channel["schemaName"] == "foxglove.SceneUpdate"
        scene = decode_protobuf(channel, client.payloads(client.subscribe("/cyborg/map_scene"))[0])
    entities = {entity.id: entity for entity in scene.entities}
    assert set(entities) == {"map/walls", "map/forbidden", "map/goals"}
    assert all(entity.frame_id == "map" for entity in entities.values())
    walls = entities["map/walls"].lines[0]
    assert len(walls.points) == 2 * 6  # the room's six walls, two ends each
    assert len(entities["map/forbidden"].lines[0].points) == 2 * 4  # the area's four edges
    goals = entities["map/goals"]
    assert sorted(text.text for text in goals.texts) == ["charger view", "window"]
    assert len(goals.arrows) == 1 and len(goals.spheres) == 1  # heading or none


def test_the_robot_frame_follows_its_odometry(served: Served) -> None:
    robot.POSE.publisher(served.publisher_node)
    odometry = robot.ODOM.publisher(served.publisher_node)

    def make(count: int) -> Odometry:
        message: Odometry = new_message(served.context.types, "nav_msgs/msg/Odometry", {
            "header": {"frame_id": "map", "stamp": {"sec": 100 + count}},
            "child_frame_id": "base_link",
            "pose": {"pose": {"position": {"x": 2.5}, "orientation": {"w": 1.0}}}})
        return message
    stream = Repeating(odometry, make)
    try:
        with served.client() as client:
            channel = client.channel("/cyborg/pose_tf")
            payload = client.payloads(client.subscribe("/cyborg/pose_tf"))[0]
    finally:
        stream.stop()
    transform = decode_protobuf(channel, payload)
    assert (transform.parent_frame_id, transform.child_frame_id) == ("map", "base_link")
    assert transform.translation.x == 2.5
    assert transform.timestamp.seconds >= 100  # stamped as the odometry is


def test_the_tree_ticks_as_json_naming_its_nodes(served: Served) -> None:
    tree = tree_from(N("Sequence", N("Scripted", id="check", title="Check battery",
                                     script="S"),
                       N("Scripted", id="drive", title="Drive", script="R"), id="seq"))
    structure = json.dumps(tree.structure.to_json())
    node = served.publisher_node
    tree_runner.STRUCTURE.publisher(node, "/cyborg/bt").publish(BehaviorTree(tree=structure))
    status = tree_runner.STATUS.publisher(node, "/cyborg/bt")

    def tick(count: int) -> BehaviorTreeStatus:
        return BehaviorTreeStatus(
            stamp=Time(sec=count, nanosec=500_000_000), tick=count + 1, duration=0.002,
            status=3, visited_ids=["check", "drive", "seq"],
            visited_statuses=np.array([1, 3, 3], np.uint8),
            visited_durations=np.array([0.001, 0.001, 0.002], np.float32),
            active_ids=["seq", "drive"], halted_ids=[], mode="")
    stream = Repeating(status, tick)
    try:
        with served.client() as client:
            channel = client.channel("/cyborg/bt/tick")
            payload = client.payloads(client.subscribe("/cyborg/bt/tick"))[0]
    finally:
        stream.stop()
    assert (channel["encoding"], channel["schemaEncoding"]) == ("json", "jsonschema")
    assert json.loads(channel["schema"])["title"] == "cyborg.TreeTick"
    message = json.loads(payload)
    assert message["status"] == "running" and message["tick"] >= 1
    assert message["duration_ms"] == 2.0
    nodes = {entry["id"]: entry for entry in message["nodes"]}
    assert nodes["check"]["title"] == "Check battery" and nodes["check"]["status"] == "success"
    assert nodes["drive"]["status"] == "running" and nodes["drive"]["ticked"] is True
    assert message["active"] == ["seq", "drive"]
    assert message["nodes"][0]["id"] == json.loads(structure)["root"]["id"]  # pre-order
