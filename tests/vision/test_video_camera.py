"""A camera without depth (a video file): the camera advertises only what it publishes, and the
detector detects on the image alone — distance unknown (NaN) — and says so in its log.

The detector pairs the image with the depth map (and the right image) only while such a topic
has a publisher in the bus graph; when images arrive but no pair completes for 5 s it warns once,
saying which topic is silent, and detects without distance until depth pairs again.
"""

from __future__ import annotations

import argparse
import logging
import math
import os
import subprocess
import sys
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import pytest

from cyborg.bus import BusConfig, Context, Node, Qos
from cyborg.bus.wire import EntityKind
from cyborg.vision import CameraTopics, DetectionPipeline, Detector, DetectorNode
from cyborg.vision.image_messages import bgr_to_image, depth_to_image
from cyborg.vision.samples import photo
from tests.conftest import shared_dir
from tests.ports import free_port
from tests.vision.test_detector_node import wait_for

MODEL = shared_dir() / "models" / "yolox_nano.onnx"
WARNING = "cyborg.vision"


def write_video(path: Path, frames: int = 4) -> Path:
    """A short MJPG video of scikit-image's astronaut photograph (a person), panning a little."""
    person = photo("astronaut")
    height, width = person.shape[:2]
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter.fourcc(*"MJPG"), 5.0, (width, height))
    assert writer.isOpened(), "OpenCV cannot write MJPG .avi here"
    for index in range(frames):
        writer.write(np.ascontiguousarray(np.roll(person, index * 8, axis=1)))
    writer.release()
    return path


class FakeClock:
    """Monotonic seconds that move only when the test says so."""

    def __init__(self, now: float = 100.0) -> None:
        self.now = now

    def __call__(self) -> float:
        return self.now


@pytest.fixture
def bus() -> Iterator[Context]:
    context = Context(BusConfig.isolated())
    yield context
    context.close()


@pytest.fixture(scope="module")
def detector() -> Detector:
    return Detector.open(MODEL, threads=1)


def publishers(bus: Context, topic: str) -> int:
    return bus.graph.count(topic, EntityKind.PUBLISHER)


def listen(bus: Context, topic: str) -> list[Any]:
    listener = Node("listener", context=bus)
    predictions: list[Any] = []
    listener.create_subscription(topic, "cyborg_msgs/msg/Predictions", predictions.append,
                                 Qos.latched())
    return predictions


def warnings_of(caplog: pytest.LogCaptureFixture) -> list[str]:
    return [record.getMessage() for record in caplog.records
            if record.levelno == logging.WARNING and record.name.startswith(WARNING)]


# ------------------------------------------------------------------ cyborg up's wiring
def test_a_video_camera_advertises_no_depth_and_the_detector_finds_the_person_without_distance(
        bus: Context, tmp_path: Path) -> None:
    from cyborg.app.launchables import starter_for
    from cyborg.app.up_vision import vision_nodes

    video = write_video(tmp_path / "walk.avi")
    args = argparse.Namespace(no_detector=False, model="yolox_nano", camera=str(video))
    specs = vision_nodes(args, "/cyborg")  # what `cyborg up --camera walk.avi` starts
    assert [spec.kind for spec in specs] == ["camera", "detector", "tracker"]
    predictions = listen(bus, "/cyborg/detector/predictions")
    running = [starter_for(spec)(bus, spec) for spec in specs]
    try:
        assert wait_for(lambda: any(p.predictions for p in predictions), timeout=20), \
            "a camera without depth must still give detections"
        found = next(p for p in reversed(predictions) if p.predictions)
        (person,) = found.predictions
        assert person.label == "person" and person.confidence > 0.8
        assert math.isnan(person.distance), "no depth: the distance is unknown, never 0"
        assert publishers(bus, "/cyborg/camera/left/image_raw") == 1
        assert publishers(bus, "/cyborg/camera/depth/depth_registered") == 0, \
            "the camera advertises no depth topic it never publishes"
        assert publishers(bus, "/cyborg/camera/right/image_raw") == 0
    finally:
        for item in reversed(running):
            item.stop()


# ------------------------------------------------------------------ the detector's log
def _detector_on_clock(bus: Context, detector: Detector) -> tuple[FakeClock, DetectorNode,
                                                                  list[Any]]:
    """A detector node on /cam/image + /cam/depth whose clock the test moves, and the
    predictions it publishes."""
    clock = FakeClock()
    node = Node("detector", "/d", context=bus)
    detector_node = DetectorNode(node, DetectionPipeline(detector),
                                 CameraTopics("/cam/image", "/cam/depth"), clock=clock)
    return clock, detector_node, listen(bus, "/d/predictions")


def test_without_a_depth_publisher_the_detector_runs_image_only_and_says_so_after_5_s(
        bus: Context, detector: Detector, caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.INFO, logger=WARNING)
    clock, detector_node, predictions = _detector_on_clock(bus, detector)
    image = Node("cam", context=bus).create_publisher("/cam/image", "sensor_msgs/msg/Image")
    person = photo("astronaut")

    def frame(stamp: int, at: float) -> None:
        clock.now = at
        count = detector_node.processed
        image.publish(bgr_to_image(person, stamp, "cam"))
        assert wait_for(lambda: detector_node.processed > count and len(predictions) >= stamp)

    frame(1, 100.0)  # no publisher of depth: the image alone is detected, at once
    (found,) = predictions[-1].predictions
    assert found.label == "person" and math.isnan(found.distance)
    frame(2, 104.9)
    assert warnings_of(caplog) == [], "images for under 5 s: no complaint yet"
    frame(3, 105.0)
    frame(4, 130.0)
    (warning,) = warnings_of(caplog)
    assert "images arrive on /cam/image but nothing is published on depth topic " \
           "/cam/depth" in warning
    assert "detecting without distance" in warning
    assert detector_node.dropped == 0 and detector_node.processed == 4


def test_a_silent_depth_publisher_is_waited_for_5_s_then_named_and_detection_goes_on(
        bus: Context, detector: Detector, caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.INFO, logger=WARNING)
    clock, detector_node, predictions = _detector_on_clock(bus, detector)
    camera = Node("cam", context=bus)
    image = camera.create_publisher("/cam/image", "sensor_msgs/msg/Image")
    depth = camera.create_publisher("/cam/depth", "sensor_msgs/msg/Image")
    assert wait_for(lambda: publishers(bus, "/cam/depth") == 1)
    person = photo("astronaut")
    three_metres = np.full(person.shape[:2], 3.0, np.float32)

    def publish(stamp: int, at: float, *, with_depth: bool = False) -> None:
        clock.now = at
        if with_depth:
            depth.publish(depth_to_image(three_metres, stamp, "cam"))
        image.publish(bgr_to_image(person, stamp, "cam"))
        assert detector_node.node.callbacks.flush()  # handled at this clock time

    depth.publish(depth_to_image(three_metres, 999, "cam"))  # matches no image
    publish(1, 100.0)
    publish(2, 104.0)
    assert not wait_for(lambda: predictions, timeout=0.5), \
        "a depth publisher exists: images wait for their depth map"
    assert warnings_of(caplog) == []
    publish(3, 105.0)  # 5 s of images without a pair: warn, and detect without distance
    assert wait_for(lambda: predictions)
    (found,) = predictions[-1].predictions
    assert found.label == "person" and math.isnan(found.distance)
    assert predictions[-1].image_header.stamp.nanosec == 3
    (warning,) = warnings_of(caplog)
    assert "images arrive on /cam/image but none paired with a depth map on /cam/depth" \
        in warning
    assert "1 received, none with an image's stamp" in warning
    assert "published by /cam;" in warning, "the warning names the silent topic's publisher"
    assert "detecting without distance" in warning
    assert detector_node.dropped == 3, "the unmatched depth map and the two images before"
    publish(4, 106.0)
    assert wait_for(lambda: len(predictions) == 2)

    publish(5, 107.0, with_depth=True)  # depth pairs again: distances come back
    assert wait_for(lambda: len(predictions) == 3)
    (found,) = predictions[-1].predictions
    assert found.distance == pytest.approx(3.0)
    assert any("pairs again" in record.getMessage() for record in caplog.records)
    publish(6, 108.0)
    assert not wait_for(lambda: len(predictions) > 3, timeout=0.5), \
        "paired again: the next image waits for its depth map"
    publish(7, 113.5)  # another 5 s without a pair: detect again, without a second warning
    assert wait_for(lambda: len(predictions) == 4)
    assert len(warnings_of(caplog)) == 1
    assert detector_node.dropped == 4, "and the image that waited in vain after the pair"


# ------------------------------------------------------------------ cyborg up, end to end
@pytest.mark.heavy
def test_cyborg_up_with_a_video_camera_detects_without_distance(tmp_path: Path) -> None:
    video = write_video(tmp_path / "walk.avi")
    port = free_port()
    process = subprocess.Popen(
        [sys.executable, "-m", "cyborg", "up", "--no-monitor", "--duration", "20",
         "--listen", f"tcp/127.0.0.1:{port}", "--camera", str(video)],
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
        env=dict(os.environ, PYTHONUNBUFFERED="1"))
    assert process.stdout is not None
    lines: list[str] = []

    def read_until(found: Callable[[str], bool]) -> None:
        assert process.stdout is not None
        while not any(found(line) for line in lines):
            line = process.stdout.readline()
            assert line, "cyborg up ended early:\n" + "".join(lines)
            lines.append(line)

    read_until(lambda line: line.lstrip().startswith("detector "))
    context = Context(BusConfig.from_environment([f"tcp/127.0.0.1:{port}"]))
    try:
        listener = Node("listener", context=context)
        predictions: list[Any] = []
        listener.create_subscription("/cyborg/detector/predictions",
                                     "cyborg_msgs/msg/Predictions", predictions.append,
                                     Qos.latched())
        assert wait_for(lambda: any(p.predictions for p in predictions), timeout=15)
        person = next(p for p in reversed(predictions) if p.predictions).predictions[0]
        assert person.label == "person" and math.isnan(person.distance)
        assert context.graph.count("/cyborg/camera/depth/depth_registered",
                                   EntityKind.PUBLISHER) == 0
        read_until(lambda line: "detecting without distance" in line)
    finally:
        context.close()
        process.terminate()
        process.communicate(timeout=30)
    warning = next(line for line in lines if "detecting without distance" in line)
    assert "/cyborg/camera/depth/depth_registered" in warning


# ------------------------------------------------------------------ the rule, without a bus
def test_inputs_wait_only_for_the_partners_that_have_a_publisher_now() -> None:
    from cyborg.vision.camera_inputs import CameraInputs

    clock = FakeClock()
    published: dict[str, list[str]] = {"/cam/depth": [], "/cam/right": []}
    inputs = CameraInputs(CameraTopics("/cam/image", "/cam/depth", "/cam/right"),
                          lambda topic: published[topic], clock=clock)
    assert inputs.add("image", 1, "i1") == {"image": "i1"}, "no partner published: at once"
    published["/cam/depth"] = ["/zed"]
    assert inputs.add("image", 2, "i2") is None
    assert inputs.add("depth", 2, "d2") == {"image": "i2", "depth": "d2"}
    clock.now += 60  # pairs keep coming: a silent right-image topic is no reason to complain
    assert inputs.add("depth", 3, "d3") is None
    assert inputs.add("image", 3, "i3") == {"image": "i3", "depth": "d3"}
    assert not inputs.complained and not inputs.starved
    published["/cam/depth"] = []  # the depth camera went away: images go on alone
    assert inputs.add("image", 4, "i4") == {"image": "i4"}
    assert inputs.dropped == 0
    assert inputs.add("depth", 5, "late") is None and inputs.dropped == 1
    early = CameraInputs(CameraTopics("/cam/image", "/cam/depth"), lambda topic: [],
                         clock=clock)  # a camera's first depth map, before the graph shows it
    assert early.add("depth", 1, "d1") is None
    assert early.add("image", 1, "i1") == {"image": "i1", "depth": "d1"}
    alone = CameraInputs(CameraTopics("/cam/image"), lambda topic: [], clock=clock)
    assert alone.add("image", 1, "i1") == {"image": "i1"}
    clock.now += 60
    assert alone.add("image", 2, "i2") == {"image": "i2"}
    assert not alone.complained, "no depth topic asked for: nothing to say"
