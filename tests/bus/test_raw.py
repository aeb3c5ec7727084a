"""Raw subscriptions get each message's CDR as it travelled: in-process, through Zenoh, through
shared memory, latched; stamped on arrival, with the sender's attachment; batched until the
node drains them."""

from __future__ import annotations

import time

import numpy as np
import pytest

from cyborg.bus import BusConfig, Context, Node, Qos, new_message
from cyborg.bus.msgs.std_msgs.msg import String
from cyborg.bus.raw import RawMessage
from tests.bus.bus_peer import linked_contexts, until_subscribed, wait_for


def big_image(context: Context) -> object:
    message = new_message(context.types, "sensor_msgs/msg/Image",
                          {"height": 300, "width": 400, "encoding": "rgb8", "step": 1200})
    message.data = np.arange(360_000, dtype=np.uint32).astype(np.uint8)
    return message


def test_in_process_messages_come_as_the_cdr_the_bus_would_send() -> None:
    with Context(BusConfig.isolated()) as context:
        talker, recorder = Node("talker", context=context), Node("recorder", context=context)
        got: list[RawMessage] = []
        recorder.create_raw_subscription("/chatter", "std_msgs/msg/String", got.append)
        publisher = talker.create_publisher("/chatter", String)
        before = time.time_ns()
        publisher.publish(String(data="hello"))
        assert wait_for(lambda: got, 10)
        raw = got[0]
        assert raw.data == bytes(context.types.serialize(String(data="hello"),
                                                          "std_msgs/msg/String"))
        assert raw.info is not None and raw.info.gid == publisher.gid
        assert before <= raw.info.timestamp_ns <= raw.received_ns <= time.time_ns()


def test_remote_messages_come_as_their_payload_small_large_and_latched() -> None:
    with linked_contexts() as (recording, publishing):
        talker, recorder = Node("talker", context=publishing), Node("rec", context=recording)
        latched = talker.create_publisher("/latched", String, Qos.latched())
        latched.publish(String(data="kept for late subscribers"))
        got: dict[str, list[RawMessage]] = {"/latched": [], "/image": []}
        recorder.create_raw_subscription("/latched", "std_msgs/msg/String",
                                         got["/latched"].append, Qos.latched())
        recorder.create_raw_subscription("/image", "sensor_msgs/msg/Image", got["/image"].append)
        camera = talker.create_publisher("/image", "sensor_msgs/msg/Image")
        until_subscribed(publishing, "/image", 20)
        assert wait_for(lambda: publishing.shm_readers("/image"), 20)  # the slot path
        image = big_image(publishing)
        camera.publish(image)
        assert wait_for(lambda: got["/latched"] and got["/image"], 20), got
        types = publishing.types
        assert got["/latched"][0].data == bytes(types.serialize(
            String(data="kept for late subscribers"), "std_msgs/msg/String"))
        assert got["/image"][0].data == bytes(types.serialize(image, "sensor_msgs/msg/Image"))
        assert len(got["/image"][0].data) > 64 * 1024


def test_a_raw_publisher_sends_the_bytes_as_they_are_remote_local_large_and_latched() -> None:
    with linked_contexts() as (listening, playing):
        player, listener = Node("player", context=playing), Node("listener", context=listening)
        types = playing.types
        text = bytes(types.serialize(String(data="as recorded"), "std_msgs/msg/String"))
        latched = player.create_raw_publisher("/map", "std_msgs/msg/String", Qos.latched())
        latched.publish_raw(text)
        camera = player.create_raw_publisher("/image", "sensor_msgs/msg/Image")
        chatter = player.create_raw_publisher("/chatter", "std_msgs/msg/String")
        got: dict[str, list[RawMessage]] = {"/map": [], "/image": [], "/chatter": []}
        local: list[String] = []
        Node("local", context=playing).create_subscription("/chatter", String, local.append)
        for topic, type_name in (("/image", "sensor_msgs/msg/Image"),
                                 ("/chatter", "std_msgs/msg/String")):
            listener.create_raw_subscription(topic, type_name, got[topic].append)
        until_subscribed(playing, "/image", 20)
        until_subscribed(playing, "/chatter", 20)
        assert wait_for(lambda: playing.shm_readers("/image"), 20)  # the slot path
        image = bytes(types.serialize(big_image(playing), "sensor_msgs/msg/Image"))
        camera.publish_raw(image)
        chatter.publish_raw(text)
        listener.create_raw_subscription("/map", "std_msgs/msg/String", got["/map"].append,
                                         Qos.latched())  # late: gets the latched bytes
        assert wait_for(lambda: all(got.values()) and local, 20), got
        assert [got[t][0].data for t in ("/map", "/image", "/chatter")] == [text, image, text]
        assert got["/chatter"][0].info is not None
        assert got["/chatter"][0].info.gid == chatter.gid
        assert local == [String(data="as recorded")]  # this process's subscribers: decoded
        chatter.destroy()
        with pytest.raises(RuntimeError, match="destroyed"):
            chatter.publish_raw(text)


def test_a_batched_subscription_waits_for_drain_and_keeps_the_newest_depth() -> None:
    with Context(BusConfig.isolated()) as context:
        talker, recorder = Node("talker", context=context), Node("recorder", context=context)
        got: list[RawMessage] = []
        subscription = recorder.create_raw_subscription(
            "/chatter", "std_msgs/msg/String", got.append, Qos(depth=3), batched=True)
        publisher = talker.create_publisher("/chatter", String)
        for i in range(5):
            publisher.publish(String(data=str(i)))
        assert recorder.callbacks.flush(10)
        assert got == []  # nothing was handed over on the node's thread
        assert subscription.backlog_peak == 3
        assert subscription.drain() == 3
        assert [context.types.deserialize(raw.data, "std_msgs/msg/String").data
                for raw in got] == ["2", "3", "4"]
        assert [raw.info.sequence for raw in got if raw.info is not None] == [3, 4, 5]
        assert subscription.drain() == 0
