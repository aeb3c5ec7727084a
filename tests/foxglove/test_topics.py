"""ROS 2 topics served to a plain Foxglove protocol client: schemas, CDR, discovery, latching."""

from __future__ import annotations

import socket

import pytest

from cyborg.bus import Qos
from cyborg.bus.msgs.geometry_msgs.msg import Pose2D
from cyborg.bus.msgs.std_msgs.msg import String
from cyborg.foxglove import FoxgloveError, FoxgloveServer
from cyborg.foxglove.schemas import ros2msg_definition
from tests.foxglove.conftest import Repeating, Served, wait_for


def test_a_topic_is_advertised_with_its_full_ros2msg_definition_and_cdr(served: Served) -> None:
    served.publisher_node.create_publisher("pose", Pose2D)
    with served.client() as client:
        assert client.until(lambda: client.server_info is not None)
        channel = client.channel("/cyborg/pose")
    assert channel["encoding"] == "cdr"
    assert channel["schemaEncoding"] == "ros2msg"
    assert channel["schemaName"] == "geometry_msgs/msg/Pose2D"
    assert channel["schema"] == ros2msg_definition(served.context.types,
                                                   "geometry_msgs/msg/Pose2D")
    assert "float64 theta" in channel["schema"]


def test_a_pose_arrives_as_the_cdr_published_and_decodes_to_it(served: Served) -> None:
    publisher = served.publisher_node.create_publisher("pose", Pose2D)
    stream = Repeating(publisher, lambda count: Pose2D(x=1.0 + count, y=-2.5, theta=0.75))
    try:
        with served.client() as client:
            subscription = client.subscribe("/cyborg/pose")
            payload = client.payloads(subscription)[0]
    finally:
        stream.stop()
    decoded = served.context.types.deserialize(payload, "geometry_msgs/msg/Pose2D")
    assert decoded in stream.sent
    assert (decoded.y, decoded.theta) == (-2.5, 0.75)
    assert payload == bytes(served.context.types.serialize(decoded, "geometry_msgs/msg/Pose2D"))


def test_the_bus_is_subscribed_only_while_a_client_watches(served: Served) -> None:
    publisher = served.publisher_node.create_publisher("pose", Pose2D)
    stream = Repeating(publisher, lambda count: Pose2D(x=float(count), y=0.0, theta=0.0))
    try:
        with served.client() as client:
            client.channel("/cyborg/pose")
            assert served.subscriptions("/cyborg/pose") == 0
            subscription = client.subscribe("/cyborg/pose")
            client.payloads(subscription)
            assert served.subscriptions("/cyborg/pose") == 1
            client.unsubscribe(subscription)
            assert client.until(lambda: served.subscriptions("/cyborg/pose") == 0)
            second = client.subscribe("/cyborg/pose")
            client.payloads(second)
        assert wait_for(lambda: served.subscriptions("/cyborg/pose") == 0)  # the client left
    finally:
        stream.stop()


def test_a_topic_published_after_connecting_is_advertised_and_one_that_vanishes_is_not(
        served: Served) -> None:
    with served.client() as client:
        assert client.until(lambda: client.server_info is not None)
        assert "/cyborg/late" not in client.channels
        late = served.publisher_node.create_publisher("late", String)
        channel = client.channel("/cyborg/late")
        assert channel["schemaName"] == "std_msgs/msg/String"
        late.destroy()
        assert client.until(lambda: "/cyborg/late" not in client.channels)


def test_a_latched_message_reaches_a_client_that_subscribes_later(served: Served) -> None:
    served.publisher_node.create_publisher("state", String, Qos.latched()).publish(
        String(data="docked"))
    with served.client() as first, served.client("foxglove.sdk.v1") as second:
        early = first.subscribe("/cyborg/state")
        assert first.channels["/cyborg/state"]["metadata"]["latched"] == "true"
        payload = first.payloads(early)[0]
        late = second.subscribe("/cyborg/state")
        again = second.payloads(late)[0]
    assert served.context.types.deserialize(payload, "std_msgs/msg/String").data == "docked"
    assert again == payload


def test_hidden_topics_are_not_offered(served: Served) -> None:
    served.publisher_node.create_publisher("_private/state", String)
    served.publisher_node.create_publisher("shown", String)
    with served.client() as client:
        client.channel("/cyborg/shown")
        assert "/cyborg/_private/state" not in client.channels


def test_a_port_in_use_is_refused_with_a_clear_error(served: Served) -> None:
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        other = FoxgloveServer(served.server.node, port=port)
        with pytest.raises(FoxgloveError, match=f"port {port} on 127.0.0.1 is in use.*--port"):
            other.start()
