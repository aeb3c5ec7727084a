"""The recorder on the bus: late topics, latched values, selection, pause, skipped types,
the one-second flush, the messages a full queue dropped."""

from __future__ import annotations

import threading
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from cyborg.bus import BusConfig, Context, Node, Qos, new_message
from cyborg.bus.msgs.std_msgs.msg import String
from cyborg.bus.msgs.std_srvs.srv import SetBool
from cyborg.bus.wire import EntityKind
from cyborg.record import mcap_file
from cyborg.record import recorder as recorder_module
from cyborg.record.recorder import Recorder
from cyborg.record.scan import scan
from cyborg.record.selection import TopicSelection
from cyborg.record.split import RecordingFiles
from tests.bus.bus_peer import wait_for
from tests.record.readers import read_mcap


@pytest.fixture
def bus() -> Iterator[Context]:
    context = Context(BusConfig.isolated())
    yield context
    context.close()


def recorder(bus: Context, path: Path, selection: TopicSelection | None = None) -> Recorder:
    return Recorder(Node("recorder", context=bus), RecordingFiles(path, bus.types),
                    selection or TopicSelection.of())


def test_topics_that_appear_after_the_start_are_recorded_from_their_first_message(
        bus: Context, tmp_path: Path) -> None:
    rec = recorder(bus, tmp_path / "run.mcap")
    talker = Node("talker", context=bus)
    late = talker.create_publisher("/late", String)
    assert wait_for(lambda: "/late" in rec.stats.topics, 10)
    for i in range(3):
        late.publish(String(data=str(i)))
    assert wait_for(lambda: rec.stats.messages == 3, 10)
    rec.close()
    assert read_mcap(tmp_path / "run.mcap") == {"/late": [{"data": "0"}, {"data": "1"},
                                                          {"data": "2"}]}


def image(bus: Context) -> object:
    message = new_message(bus.types, "sensor_msgs/msg/Image",
                          {"height": 1, "width": 2, "encoding": "mono8", "step": 2})
    message.data = np.array([1, 2], dtype=np.uint8)
    return message


@pytest.mark.parametrize(("selection", "recorded"), [
    (TopicSelection.of(), {"/a/log", "/b/log"}),
    (TopicSelection.of(images=True), {"/a/log", "/b/log", "/camera/image"}),
    (TopicSelection.of(exclude=["/b/*"]), {"/a/log"}),
    (TopicSelection.of(["/camera/image", "b/log"]), {"/camera/image", "/b/log"}),
    (TopicSelection.of(["/a/_hidden"]), {"/a/_hidden"}),
])
def test_all_topics_but_hidden_and_images_unless_named_or_asked(
        bus: Context, tmp_path: Path, selection: TopicSelection, recorded: set[str]) -> None:
    talker = Node("talker", context=bus)
    publishers = [talker.create_publisher(topic, String)
                  for topic in ("/a/log", "/b/log", "/a/_hidden")]
    camera = talker.create_publisher("/camera/image", "sensor_msgs/msg/Image")
    assert wait_for(lambda: len(bus.graph.entities([EntityKind.PUBLISHER])) == 4, 10)
    rec = recorder(bus, tmp_path / "run.mcap", selection)  # sees them all at once
    for publisher in publishers:
        publisher.publish(String(data="x"))
    camera.publish(image(bus))
    assert wait_for(lambda: rec.stats.messages == len(recorded), 10)
    rec.close()
    assert set(read_mcap(tmp_path / "run.mcap")) == recorded


def test_latched_values_published_before_the_start_are_recorded(bus: Context,
                                                                 tmp_path: Path) -> None:
    talker = Node("talker", context=bus)
    talker.create_publisher("/map", String, Qos.latched()).publish(String(data="the map"))
    assert wait_for(lambda: bus.graph.count("/map", EntityKind.PUBLISHER) == 1, 10)
    rec = recorder(bus, tmp_path / "run.mcap")
    assert wait_for(lambda: rec.stats.messages == 1, 10)
    rec.close()
    assert read_mcap(tmp_path / "run.mcap") == {"/map": [{"data": "the map"}]}


def test_the_pause_service_pauses_and_resumes(bus: Context, tmp_path: Path) -> None:
    talker = Node("talker", context=bus)
    publisher = talker.create_publisher("/log", String)
    rec = recorder(bus, tmp_path / "run.mcap")
    assert wait_for(lambda: "/log" in rec.stats.topics, 10)
    pause = talker.create_client("/recorder/pause", SetBool)
    assert pause.wait_for_service(10)

    def send(text: str) -> None:
        done = rec.stats.messages + rec.stats.paused_drops
        publisher.publish(String(data=text))
        assert wait_for(lambda: rec.stats.messages + rec.stats.paused_drops > done, 10)

    send("before")
    assert pause.call(SetBool.Request(data=True), timeout=10).message == "paused"
    send("while paused")
    assert pause.call(SetBool.Request(data=False), timeout=10).message == "recording"
    send("after")
    rec.toggle_pause()
    send("paused by a signal")
    rec.close()
    assert read_mcap(tmp_path / "run.mcap") == {"/log": [{"data": "before"}, {"data": "after"}]}
    assert rec.stats.paused_drops == 2


def test_topics_of_unknown_types_are_skipped_and_named(bus: Context, tmp_path: Path) -> None:
    bus.graph.add("@ros2_lv/0/aaaa/1/2/MP/%/%/peer/%strange/their_msgs::msg::dds_::Odd_/"
                  "RIHS01_00/::,:,:,:,,")
    rec = recorder(bus, tmp_path / "run.mcap")
    rec.close()
    assert rec.stats.skipped == {"/strange": "unknown type their_msgs/msg/Odd"}


def test_an_open_chunk_reaches_the_file_within_the_flush_interval(
        bus: Context, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(mcap_file, "FLUSH_INTERVAL", 0.2)
    talker = Node("talker", context=bus)
    publisher = talker.create_publisher("/log", String)
    rec = recorder(bus, tmp_path / "run.mcap")
    assert wait_for(lambda: "/log" in rec.stats.topics, 10)
    publisher.publish(String(data="soon on disk"))
    assert wait_for(lambda: scan(tmp_path / "run.mcap").message_count == 1, 10)
    rec.close()


def test_messages_the_full_queue_dropped_are_counted_and_the_rest_written(
        bus: Context, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(recorder_module, "QUEUE_DEPTH", 3)
    talker = Node("talker", context=bus)
    publisher = talker.create_publisher("/log", String)
    rec = recorder(bus, tmp_path / "run.mcap")
    assert wait_for(lambda: "/log" in rec.stats.topics, 10)
    publisher.publish(String(data="first"))  # the publisher's sequence starts here
    assert wait_for(lambda: rec.stats.messages == 1, 10)
    busy, release = threading.Event(), threading.Event()

    def writer_busy() -> None:
        busy.set()
        release.wait(30)
    rec.node.callbacks.submit(writer_busy)
    assert busy.wait(10)
    for i in range(10):
        publisher.publish(String(data=str(i)))
    release.set()
    assert wait_for(lambda: rec.stats.messages == 4, 10)
    publisher.publish(String(data="after"))
    assert wait_for(lambda: rec.stats.messages == 5, 10)
    rec.close()
    assert rec.stats.dropped == 7
    assert rec.backlog_peak == 3
    assert read_mcap(tmp_path / "run.mcap") == {
        "/log": [{"data": "first"}, {"data": "7"}, {"data": "8"}, {"data": "9"}, {"data": "after"}]}


def test_messages_that_arrived_just_before_the_close_are_written(
        bus: Context, tmp_path: Path) -> None:
    talker = Node("talker", context=bus)
    publisher = talker.create_publisher("/log", String)
    rec = recorder(bus, tmp_path / "run.mcap")
    assert wait_for(lambda: "/log" in rec.stats.topics, 10)
    for i in range(5):  # queued for the recorder at once (in-process), written in a batch
        publisher.publish(String(data=str(i)))
    rec.close()
    assert read_mcap(tmp_path / "run.mcap") == {"/log": [{"data": str(i)} for i in range(5)]}
