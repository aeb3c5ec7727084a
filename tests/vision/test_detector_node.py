"""The detector node on the bus, model files (search and a checked download), ``cyborg detect``
and the camera and detector ``cyborg up`` starts."""

from __future__ import annotations

import hashlib
import http.server
import json
import math
import os
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator
from dataclasses import replace
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import pytest

from cyborg.app.cli import main
from cyborg.bus import BusConfig, Context, Node, Qos
from cyborg.vision import (
    CameraNode,
    CameraTopics,
    DetectionPipeline,
    Detector,
    DetectorNode,
    VisionError,
)
from cyborg.vision.models import CATALOGUE, fetch, find_model
from cyborg.vision.samples import SampleSource, photo
from tests.conftest import shared_dir
from tests.ports import free_port

MODEL = shared_dir() / "models" / "yolox_nano.onnx"


def wait_for(predicate: Callable[[], object], timeout: float = 10.0) -> bool:
    deadline = time.monotonic() + timeout
    while not predicate() and time.monotonic() < deadline:
        time.sleep(0.01)
    return bool(predicate())


@pytest.fixture
def bus() -> Iterator[Context]:
    context = Context(BusConfig.isolated())
    yield context
    context.close()


@pytest.fixture(scope="module")
def detector() -> Detector:
    return Detector.open(MODEL, threads=1)


# ------------------------------------------------------------------ the detector node
def test_the_node_runs_the_network_only_while_someone_listens(bus: Context,
                                                              detector: Detector) -> None:
    camera_node = Node("camera", "/cyborg/camera", context=bus)
    camera = CameraNode(camera_node, lambda: SampleSource("motorcycle"), rate=20.0)
    node = Node("detector", "/cyborg/detector", context=bus)
    topics = CameraTopics("/cyborg/camera/left/image_raw",
                          "/cyborg/camera/depth/depth_registered")
    detector_node = DetectorNode(node, DetectionPipeline(detector), topics)
    camera.start()
    try:
        assert wait_for(lambda: detector_node.skipped >= 3)
        assert detector_node.processed == 0, "nobody listens: the network never ran"

        listener = Node("listener", context=bus)
        predictions: list[Any] = []
        arrays: list[Any] = []
        listener.create_subscription("/cyborg/detector/predictions",
                                     "cyborg_msgs/msg/Predictions", predictions.append,
                                     Qos.latched())
        listener.create_subscription("/cyborg/detector/detections",
                                     "vision_msgs/msg/Detection2DArray", arrays.append)
        assert wait_for(lambda: len(predictions) >= 2 and arrays)
        (bike,) = predictions[-1].predictions
        assert bike.label == "motorcycle" and bike.confidence > 0.8
        assert bike.distance == pytest.approx(2.376, abs=0.02)
        corners = [(round(p.x), round(p.y)) for p in bike.bounding_box.points]
        assert corners == [(110, 67), (709, 67), (709, 446), (110, 446)]
        assert predictions[-1].image_header.frame_id == "camera_left"
        (detection,) = arrays[-1].detections
        assert detection.results[0].hypothesis.class_id == "motorcycle"
        assert detection.results[0].pose.pose.position.z == pytest.approx(bike.distance)
        assert detection.bbox.size_x == pytest.approx(599, abs=1)
        assert detector_node.last is not None and detector_node.last.annotated is None, \
            "nobody watches the annotated image: it is not drawn"

        images: list[Any] = []
        listener.create_subscription("/cyborg/detector/detection_image",
                                     "sensor_msgs/msg/Image", images.append)
        assert wait_for(lambda: images)
        assert (images[-1].width, images[-1].height, images[-1].encoding) == (741, 500, "bgr8")

        # runtime parameters: a threshold above the bike's confidence, then a class filter
        node.parameters.set({"confidence_threshold": 0.95})
        count = len(predictions)
        assert wait_for(lambda: len(predictions) > count + 1)
        assert predictions[-1].predictions == []
        node.parameters.set({"confidence_threshold": 0.3, "classes": ["dog"]})
        count = len(predictions)
        assert wait_for(lambda: len(predictions) > count + 1)
        assert predictions[-1].predictions == []
        with pytest.raises(ValueError, match="unknown labels 'unicorn'"):
            node.parameters.set({"classes": ["unicorn"]})
        with pytest.raises(ValueError):
            node.parameters.set({"confidence_threshold": 1.5})
        assert detector.classes == frozenset({"dog"})
    finally:
        camera.stop()
        detector.classes, detector.confidence = frozenset(), 0.5


class _SlowPipeline(DetectionPipeline):
    """A pipeline that, in the middle of a frame, waits until its node is being destroyed."""

    node: Node
    started: threading.Event

    def process(self, frame: Any, *, draw: bool = False) -> Any:
        result = super().process(frame, draw=draw)
        self.started.set()
        wait_for(lambda: self.node.destroyed, 10.0)
        return result


def test_a_node_destroyed_while_it_processes_a_frame_ends_it_quietly(
        bus: Context, detector: Detector, caplog: pytest.LogCaptureFixture) -> None:
    camera_node = Node("camera", "/cyborg/camera", context=bus)
    camera = CameraNode(camera_node, lambda: SampleSource("motorcycle"), rate=20.0)
    node = Node("detector", "/cyborg/detector", context=bus)
    pipeline = _SlowPipeline(detector)
    pipeline.node, pipeline.started = node, threading.Event()
    detector_node = DetectorNode(node, pipeline, CameraTopics(
        "/cyborg/camera/left/image_raw", "/cyborg/camera/depth/depth_registered"))
    listener = Node("listener", context=bus)
    listener.create_subscription("/cyborg/detector/predictions", "cyborg_msgs/msg/Predictions",
                                 lambda _message: None, Qos.latched())
    camera.start()
    try:
        assert pipeline.started.wait(30), "no frame reached the network"
        node.destroy()  # what a stopping launch does while the frame is in the network
        assert wait_for(lambda: detector_node.processed >= 1)
        time.sleep(0.2)  # the callback's publishing, had it failed, would be logged by now
        assert not [record for record in caplog.records if record.levelname == "ERROR"]
    finally:
        camera.stop()


def test_distance_is_nan_without_depth_and_frames_pair_by_exact_stamp(bus: Context,
                                                                       detector: Detector
                                                                       ) -> None:
    node = Node("detector", "/d", context=bus)
    detector_node = DetectorNode(node, DetectionPipeline(detector),
                                 CameraTopics("/cam/image", "/cam/depth"))
    listener = Node("listener", context=bus)
    predictions: list[Any] = []
    listener.create_subscription("/d/predictions", "cyborg_msgs/msg/Predictions",
                                 predictions.append, Qos.latched())
    from cyborg.vision.image_messages import bgr_to_image, depth_to_image
    camera = Node("cam", context=bus)
    image_pub = camera.create_publisher("/cam/image", "sensor_msgs/msg/Image")
    depth_pub = camera.create_publisher("/cam/depth", "sensor_msgs/msg/Image")
    assert wait_for(lambda: detector_node.watched())
    # depth is waited for only once its publisher is in the graph
    assert wait_for(lambda: detector_node.publishers("/cam/depth") == ["/cam"])
    person = photo("astronaut")
    holes = np.full(person.shape[:2], np.nan, np.float32)
    holes[::2] = np.inf
    image_pub.publish(bgr_to_image(person, 1_000, "cam"))  # never gets its depth
    depth_pub.publish(depth_to_image(holes, 2_000, "cam"))
    image_pub.publish(bgr_to_image(person, 2_000, "cam"))
    assert wait_for(lambda: predictions)
    (found,) = predictions[-1].predictions
    assert found.label == "person" and math.isnan(found.distance)
    assert predictions[-1].image_header.stamp.nanosec == 2_000
    assert detector_node.dropped == 1 and detector_node.processed == 1
    wrong = depth_to_image(np.ones((10, 10), np.float32), 3_000, "cam")
    depth_pub.publish(wrong)
    image_pub.publish(bgr_to_image(person, 3_000, "cam"))
    assert wait_for(lambda: detector_node.failed == 1), "a wrong-size depth map is refused"
    assert detector_node.processed == 1


# ------------------------------------------------------------------ model files
class _Files(http.server.SimpleHTTPRequestHandler):
    def log_message(self, *args: Any) -> None:
        pass


@pytest.fixture
def http_server(tmp_path: Path) -> Iterator[str]:
    served = tmp_path / "served"
    served.mkdir()
    (served / "yolox_nano.onnx").write_bytes(MODEL.read_bytes())

    def handler(*args: Any, **kwargs: Any) -> _Files:
        return _Files(*args, directory=str(served), **kwargs)
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    yield f"http://127.0.0.1:{server.server_address[1]}"
    server.shutdown()
    server.server_close()


def test_fetch_checks_the_sha256_and_keeps_nothing_on_a_mismatch(tmp_path: Path,
                                                                  http_server: str) -> None:
    url = f"{http_server}/yolox_nano.onnx"
    known = CATALOGUE["yolox_nano"]
    # the shared copy is a different export than the catalogue's release asset
    with pytest.raises(VisionError, match="does not match the expected c789161e"):
        fetch(known, tmp_path / "models", url=url)
    assert list((tmp_path / "models").iterdir()) == []
    same = replace(known, sha256=hashlib.sha256(MODEL.read_bytes()).hexdigest())
    seen: list[tuple[int, int]] = []
    path = fetch(same, tmp_path / "models", url=url, progress=lambda d, t: seen.append((d, t)))
    assert path == tmp_path / "models" / "yolox_nano.onnx"
    assert path.read_bytes() == MODEL.read_bytes()
    assert seen[-1] == (MODEL.stat().st_size, MODEL.stat().st_size)
    with pytest.raises(VisionError, match=r"cannot download yolox_nano from .*missing\.onnx"):
        fetch(same, tmp_path / "other", url=f"{http_server}/missing.onnx")
    assert list((tmp_path / "other").iterdir()) == []


def test_models_are_found_by_path_or_name(tmp_path: Path, monkeypatch: pytest.MonkeyPatch
                                          ) -> None:
    monkeypatch.setenv("CYBORG_MODELS", str(tmp_path))
    monkeypatch.setenv("CYBORG_SHARED", str(tmp_path / "elsewhere"))
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    with pytest.raises(VisionError, match=r"model 'yolox_nano' not found in .*elsewhere/models,"
                                          r" .*cache/cyborg/models; fetch it with `cyborg detect "
                                          r"models fetch yolox_nano`"):
        find_model("yolox_nano")
    # without CYBORG_SHARED, the shared folder beside the checkout (where the tests found it)
    monkeypatch.delenv("CYBORG_SHARED")
    import cyborg.vision.models as models
    beside = Path(models.__file__).resolve().parents[3].parent / "shared" / "models"
    if beside.is_dir():
        assert find_model("yolox_nano") == beside / "yolox_nano.onnx"
    else:
        with pytest.raises(VisionError, match="not found"):
            find_model("yolox_nano")
    (tmp_path / "yolox_nano.onnx").write_bytes(b"x")
    assert find_model("yolox_nano") == tmp_path / "yolox_nano.onnx"
    assert find_model(str(MODEL)) == MODEL
    with pytest.raises(VisionError, match=r"model file .*none\.onnx: not found"):
        find_model(str(tmp_path / "none.onnx"))
    with pytest.raises(VisionError, match="known models: yolox_nano"):
        find_model("mystery")


def test_cyborg_detect_models_fetch_against_a_local_server(
        tmp_path: Path, http_server: str, capsys: pytest.CaptureFixture[str]) -> None:
    code = main(["detect", "models", "fetch", "yolox_nano", "--dir", str(tmp_path),
                 "--url", f"{http_server}/yolox_nano.onnx"])
    assert code == 1, "the shared export is not the catalogue's file: refused"
    assert "does not match" in capsys.readouterr().err
    assert not (tmp_path / "yolox_nano.onnx").exists()
    assert main(["detect", "models", "fetch", "yolo99"]) == 1
    assert "unknown model 'yolo99'" in capsys.readouterr().err


# ------------------------------------------------------------------ cyborg detect
def test_cyborg_detect_writes_json_and_an_annotated_video(tmp_path: Path,
                                                         capsys: pytest.CaptureFixture[str]
                                                         ) -> None:
    frames = tmp_path / "frames"
    frames.mkdir()
    person = photo("astronaut")
    for index in range(3):
        cv2.imwrite(str(frames / f"{index:04d}.png"), np.roll(person, index * 20, axis=1))
    out, records = tmp_path / "out.avi", tmp_path / "found.jsonl"
    assert main(["detect", str(frames), "--model", str(MODEL), "--out", str(out),
                 "--json", str(records), "--threads", "1"]) == 0
    report = capsys.readouterr().out
    assert "3 frames: person 3" in report and f"written to {out}" in report
    lines = [json.loads(line) for line in records.read_text().splitlines()]
    assert [line["index"] for line in lines] == [0, 1, 2]
    assert all(line["detections"][0]["label"] == "person" for line in lines)
    assert lines[0]["detections"][0]["distance"] is None
    video = cv2.VideoCapture(str(out))
    assert int(video.get(cv2.CAP_PROP_FRAME_COUNT)) == 3
    video.release()


def test_cyborg_detect_on_the_stereo_sample_and_its_errors(tmp_path: Path,
                                                          capsys: pytest.CaptureFixture[str]
                                                          ) -> None:
    assert main(["detect", "sample:motorcycle", "--threads", "1"]) == 0
    assert "motorcycle: 0.90 (2.3" in capsys.readouterr().out
    assert main(["detect", str(tmp_path / "nothing.png")]) == 1
    assert "nothing.png: not found" in capsys.readouterr().err
    assert main(["detect", "sample:astronaut", "--model", str(tmp_path / "gone.onnx")]) == 1
    assert "gone.onnx: not found" in capsys.readouterr().err
    assert main(["detect", "sample:astronaut", "--classes", "unicorn"]) == 1
    assert "unknown labels unicorn" in capsys.readouterr().err
    assert main(["detect", "a.png", "b.png"]) == 1
    assert "LEFT,RIGHT" in capsys.readouterr().err
    assert main(["detect", "sample:astronaut", "--focal", "700"]) == 1
    assert "both --focal and --baseline" in capsys.readouterr().err
    assert main(["detect", "sample:astronaut", "--out", str(tmp_path / "x.docx")]) == 1
    assert "--out" in capsys.readouterr().err


# ------------------------------------------------------------------ cyborg up
@pytest.mark.heavy
def test_cyborg_up_detects_the_motorcycle_in_the_sample_stereo_frames() -> None:
    port = free_port()
    process = subprocess.Popen(
        [sys.executable, "-m", "cyborg", "up", "--no-monitor", "--camera", "real",
         "--duration", "15", "--listen", f"tcp/127.0.0.1:{port}"],
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
        env=dict(os.environ, PYTHONUNBUFFERED="1"))
    assert process.stdout is not None
    lines: list[str] = []
    while not any(line.lstrip().startswith("detector ") for line in lines):
        line = process.stdout.readline()
        assert line, "cyborg up ended before starting the detector:\n" + "".join(lines)
        lines.append(line)
    context = Context(BusConfig.from_environment([f"tcp/127.0.0.1:{port}"]))
    try:
        listener = Node("listener", context=context)
        predictions: list[Any] = []
        listener.create_subscription("/cyborg/detector/predictions",
                                     "cyborg_msgs/msg/Predictions", predictions.append,
                                     Qos.latched())
        assert wait_for(lambda: predictions, timeout=15)
        (bike,) = predictions[-1].predictions
        assert bike.label == "motorcycle" and bike.distance == pytest.approx(2.376, abs=0.02)
    finally:
        context.close()
        process.terminate()
        process.communicate(timeout=30)
    assert "camera       /cyborg/camera/camera: sample:motorcycle" in "".join(lines)


def test_launch_kinds_refuse_bad_sources_and_models_naming_the_entry(bus: Context,
                                                                       tmp_path: Path) -> None:
    from cyborg.app.launchables import starter_for
    from cyborg.bus.component import LaunchError, NodeSpec

    def start(kind: str, parameters: dict[str, Any]) -> Any:
        spec = NodeSpec(kind, kind, "/cyborg", parameters, base=tmp_path,
                        where=f"robot.toml: node {kind}")
        return starter_for(spec)(bus, spec)

    with pytest.raises(LaunchError, match=r"robot.toml: node camera: source .*ride\.mp4: not "
                                          r"found"):
        start("camera", {"source": "ride.mp4"})
    pair = photo("camera")
    for name in ("l.png", "r.png"):
        cv2.imwrite(str(tmp_path / name), pair)
    camera = start("camera", {"source": "l.png, r.png", "rate": 50.0, "loop": False})
    try:  # a stereo pair relative to the launch file opens from any working folder
        assert wait_for(lambda: camera.camera.published == 1)
        assert camera.camera.error is None
    finally:
        camera.stop()
    with pytest.raises(LaunchError, match="node camera: the camera needs a `source`"):
        start("camera", {})
    with pytest.raises(LaunchError, match=r"node detector: model file .*gone\.onnx: not found"):
        start("detector", {"model": "gone.onnx"})
    with pytest.raises(LaunchError, match="right_topic needs focal and baseline"):
        start("detector", {"model": str(MODEL), "right_topic": "/cam/right"})
    running = start("detector", {"model": str(MODEL), "threads": 1, "classes": ["person"]})
    assert wait_for(lambda: "/cyborg/detector" in bus.graph.nodes())
    try:
        assert "yolox_nano.onnx (yolox, onnxruntime)" in running.describe()
        assert running.detector.pipeline.detector.classes == frozenset({"person"})
    finally:
        running.stop()
    assert wait_for(lambda: "/cyborg/detector" not in bus.graph.nodes())


def test_sources_are_anchored_to_a_folder_except_devices_samples_and_topics() -> None:
    from cyborg.vision.sources import anchored

    base = Path("/data/run1")
    assert anchored("ride.mp4", base) == "/data/run1/ride.mp4"
    assert anchored("l.png, r.png", base) == "/data/run1/l.png,/data/run1/r.png"
    assert anchored("/abs/l.png,r.png", base) == "/abs/l.png,/data/run1/r.png"
    for untouched in ("camera:1", "0", "sample:motorcycle", "bus:/cam/image"):
        assert anchored(untouched, base) == untouched


def test_bus_source_pairs_camera_topics_into_frames(bus: Context) -> None:
    from cyborg.vision.bus_source import BusSource
    from cyborg.vision.image_messages import bgr_to_image, depth_to_image

    reader = Node("reader", context=bus)
    source = BusSource(reader, CameraTopics("/cam/image", "/cam/depth"), idle_timeout=0.5)
    camera = Node("cam", context=bus)
    image_pub = camera.create_publisher("/cam/image", "sensor_msgs/msg/Image")
    depth_pub = camera.create_publisher("/cam/depth", "sensor_msgs/msg/Image")
    left = np.zeros((4, 6, 3), np.uint8)
    left[1, 2] = (1, 2, 3)
    depth = np.full((4, 6), 1.25, np.float32)
    image_pub.publish(bgr_to_image(left, 10, "cam"))  # its depth never comes
    assert reader.callbacks.flush()  # keep-last 2: a burst of three could drop one
    for stamp in (20, 30):
        depth_pub.publish(depth_to_image(depth * stamp, stamp, "cam"))
        image_pub.publish(bgr_to_image(left, stamp, "cam"))
        assert reader.callbacks.flush()
    frames = list(source)  # ends after 0.5 s without a frame
    assert [frame.stamp_ns for frame in frames] == [20, 30]
    assert frames[1].left[1, 2].tolist() == [1, 2, 3] and frames[1].frame_id == "cam"
    assert frames[1].depth is not None and float(frames[1].depth[0, 0]) == 37.5
    assert source.total_dropped == 1
    wrong = BusSource(reader, CameraTopics("/bad/image", "/bad/depth"), idle_timeout=0.5)
    bad = camera.create_publisher("/bad/image", "sensor_msgs/msg/Image")
    bad_depth = camera.create_publisher("/bad/depth", "sensor_msgs/msg/Image")
    bad_depth.publish(depth_to_image(np.ones((2, 2), np.float32), 5, "cam"))
    bad.publish(bgr_to_image(left, 5, "cam"))
    with pytest.raises(VisionError, match="bus /bad/image: depth map is 2x2 but the image is"):
        list(wrong)
