"""Which channels the bus graph calls for: its topics, and the made ones of robots and trees."""

from __future__ import annotations

import pytest

from cyborg.bus import MessageTypes, Qos
from cyborg.bus.graph import GraphEntity
from cyborg.bus.wire import EntityKind
from cyborg.foxglove.catalogue import wanted_channels


def publisher(topic: str, type_name: str, latched: bool = False) -> GraphEntity:
    package, kind, name = type_name.split("/")
    qos = Qos.latched() if latched else Qos()
    return GraphEntity(key=f"k{topic}{type_name}{latched}", domain=0, zid="z", node_id=1,
                       entity_id=2, kind=EntityKind.PUBLISHER, enclave="", namespace="/",
                       node="n", topic=topic, dds_type=f"{package}::{kind}::dds_::{name}_",
                       qos=qos.to_keyexpr())


@pytest.fixture(scope="module")
def types() -> MessageTypes:
    return MessageTypes()


def test_topics_pass_through_with_their_type_and_latching(types: MessageTypes) -> None:
    wanted = wanted_channels([publisher("/a", "std_msgs/msg/String"),
                              publisher("/b", "std_msgs/msg/String", latched=True),
                              publisher("/b", "std_msgs/msg/String")], types)
    assert (wanted["/a"].kind, wanted["/a"].type_name, wanted["/a"].latched) == \
        ("topic", "std_msgs/msg/String", False)
    assert wanted["/b"].latched  # one latched publisher is enough


def test_hidden_and_unknown_topics_are_left_out_and_said_once(
        types: MessageTypes, caplog: pytest.LogCaptureFixture) -> None:
    warned: set[str] = set()
    entities = [publisher("/x/_action/status", "std_msgs/msg/String"),
                publisher("/custom", "their_msgs/msg/Thing")]
    assert wanted_channels(entities, types, warned) == {}
    wanted_channels(entities, types, warned)
    assert caplog.text.count("their_msgs/msg/Thing is not known here") == 1


def test_robots_and_tree_runners_get_made_channels(types: MessageTypes) -> None:
    wanted = wanted_channels([
        publisher("/r1/pose", "geometry_msgs/msg/Pose2D"),
        publisher("/r1/map_geometry", "cyborg_msgs/msg/MapGeometry", latched=True),
        publisher("/r1/odom", "nav_msgs/msg/Odometry"),
        publisher("/r2/pose", "geometry_msgs/msg/Pose2D"),  # no map, no odometry
        publisher("/r1/bt/behavior_tree", "cyborg_msgs/msg/BehaviorTree", latched=True),
        publisher("/r1/bt/status", "cyborg_msgs/msg/BehaviorTreeStatus"),
        publisher("/r1/map", "std_msgs/msg/String")], types)  # the made grid takes the name
    made = {topic: offer.kind for topic, offer in wanted.items() if offer.kind != "topic"}
    assert made == {"/r1/map": "map", "/r1/map_scene": "map_scene", "/r1/pose_tf": "frame",
                    "/r1/bt/tick": "tick"}
    assert wanted["/r1/map"].namespace == "/r1"
    assert {"/r1/pose", "/r2/pose", "/r1/odom", "/r1/bt/status"} <= set(wanted)
