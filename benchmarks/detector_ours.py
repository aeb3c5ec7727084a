"""Our detector in the benchmark: the real DetectorNode on the bus, and bare inference.

* :class:`OursInProcess`: camera and detector nodes on one bus context, as ``cyborg up`` runs
  them (in-process delivery: the frame is handed over, not copied).
* :class:`OursTwoProcesses`: a camera node here (with the bus router) publishing each frame as
  two ``sensor_msgs/Image`` (``bgr8`` + ``32FC1``, CameraNode's topics and encodings), the
  detector node in a process of its own (``python3 -m benchmarks.detector --detector-peer``);
  the camera hears the ``Detection2DArray`` back, which gives the latency.
* :class:`PipelineAlone`: :class:`~cyborg.vision.DetectionPipeline` on the frames, no bus: frame
  in, detections with distances (and the annotated image when drawn) out.
* :class:`BareInference`: the onnxruntime session alone on a tensor prepared once.

In both bus configurations a viewer in the detector's process may subscribe to
``detection_image`` (:class:`Viewer`): while it does, the node draws the annotated image.
"""

from __future__ import annotations

import json
import socket
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

from benchmarks.detector_frames import THRESHOLD, Frames, Offer, Run, offer_frames, stages_of
from cyborg.bus import BusConfig, Context, Node, Qos
from cyborg.vision import CameraTopics, DetectorNode
from cyborg.vision.backends import OnnxRuntimeBackend
from cyborg.vision.detector import Detector
from cyborg.vision.frames import Frame
from cyborg.vision.image_messages import bgr_to_image, depth_to_image, stamp_ns
from cyborg.vision.pipeline import DetectionPipeline, Result

IMAGE_TOPIC, DEPTH_TOPIC = "/camera/left/image_raw", "/camera/depth/depth_registered"
DETECTIONS_TOPIC, ANNOTATED_TOPIC = "/detector/detections", "/detector/detection_image"
"""The benchmark's entry point, which runs the detector process with ``--detector-peer``."""


class TimedPipeline(DetectionPipeline):
    """The pipeline, remembering when its last ``process`` started and ended."""

    started = ended = 0

    def process(self, frame: Frame, *, draw: bool = False) -> Result:
        self.started = time.time_ns()
        result = super().process(frame, draw=draw)
        self.ended = time.time_ns()
        return result


class TimedDetectorNode(DetectorNode):
    """The detector node, recording per frame when it arrived and what each stage took."""

    def __init__(self, node: Node, pipeline: TimedPipeline, topics: CameraTopics) -> None:
        super().__init__(node, pipeline, topics)
        self.timed = pipeline
        self.records: list[dict[str, float]] = []

    def _on_frame(self, messages: dict[str, Any]) -> None:
        arrived = time.time_ns()
        processed = self.processed
        super()._on_frame(messages)
        done = time.time_ns()
        if self.processed == processed or self.last is None:
            return  # skipped or failed: counted by the node
        times = self.last.times
        stamp = stamp_ns(messages["image"].header)
        self.records.append({
            "transport": (arrived - stamp) / 1e6,
            "message → frame": (self.timed.started - arrived) / 1e6,
            "preprocess": times["preprocess"] * 1e3, "inference": times["inference"] * 1e3,
            "postprocess": times["postprocess"] * 1e3,
            "distance": (times["distance"] + times["depth"]) * 1e3,
            "drawing": times["drawing"] * 1e3, "publish": (done - self.timed.ended) / 1e6,
            "detections": float(len(self.last.detections))})


class Viewer:
    """A subscriber to ``detection_image`` in the detector's process: while there is one, the
    detector node draws the annotated image and publishes it."""

    def __init__(self, context: Context) -> None:
        self.context = context
        self.node: Node | None = None

    def watch(self, on: bool) -> None:
        if on and self.node is None:
            self.node = Node("viewer", context=self.context)
            self.node.create_subscription(ANNOTATED_TOPIC, "sensor_msgs/msg/Image",
                                          lambda _m: None, Qos(depth=1))
        elif not on and self.node is not None:
            self.node.destroy()
            self.node = None


def start_detector(context: Context, model: Path,
                   threads: int) -> tuple[TimedDetectorNode, Viewer]:
    """The detector node and, in its process, a viewer of the annotated image (watching)."""
    detector = Detector.open(model, threads=threads, confidence=THRESHOLD)
    node = Node("detector", namespace="/detector", context=context)
    detector_node = TimedDetectorNode(node, TimedPipeline(detector),
                                      CameraTopics(image=IMAGE_TOPIC, depth=DEPTH_TOPIC))
    viewer = Viewer(context)
    viewer.watch(True)
    return detector_node, viewer


def detector_peer(endpoint: str, model: Path, threads: int) -> None:
    """The detector process: answers ``report`` on stdin with its records since the last one;
    ``draw`` and ``no-draw`` start and stop its viewer (answered ``ok``)."""
    context = Context(BusConfig(connect=(endpoint,)))
    detector, viewer = start_detector(context, model, threads)
    print("ready", flush=True)
    for line in sys.stdin:
        command = line.strip()
        if command == "report":
            records, detector.records = detector.records, []
            print(json.dumps({"records": records,
                              "dropped": detector.dropped + detector.failed,
                              "bus": dict(context.dropped)}), flush=True)
        elif command in ("draw", "no-draw"):
            viewer.watch(command == "draw")
            print("ok", flush=True)
    context.close()


class Camera:
    """The camera node: publishes frames (as CameraNode does), hears the detections back."""

    def __init__(self, context: Context, frames: Frames) -> None:
        self.node = Node("camera", namespace="/camera", context=context)
        self.frames = frames
        self.image = self.node.create_publisher(IMAGE_TOPIC, "sensor_msgs/msg/Image",
                                                Qos(depth=2))
        self.depth = self.node.create_publisher(DEPTH_TOPIC, "sensor_msgs/msg/Image",
                                                Qos(depth=2))
        self.offer = Offer(1)
        self.node.create_subscription(
            DETECTIONS_TOPIC, "vision_msgs/msg/Detection2DArray",
            lambda message: self.offer.answer(stamp_ns(message.header)), Qos(depth=5))

    def send(self, stamp: int, index: int) -> None:
        image, depth = self.frames[index % len(self.frames)]
        self.image.publish(bgr_to_image(image, stamp, "camera_left"))
        self.depth.publish(depth_to_image(depth, stamp, "camera_left"))

    def run(self, count: int, window: int) -> Run:
        self.offer = Offer(window)
        return offer_frames(self.send, self.offer, count)


class OursInProcess:
    """Camera and detector nodes on one bus context, as ``cyborg up`` runs them."""

    def __init__(self, frames: Frames, model: Path, threads: int) -> None:
        self.context = Context(BusConfig.isolated())
        self.detector, self.viewer = start_detector(self.context, model, threads)
        self.camera = Camera(self.context, frames)
        self.dropped = 0

    def run(self, count: int, window: int, *, draw: bool = True) -> Run:
        """``count`` frames, ``window`` in flight; ``draw``: with a viewer of the annotated
        image (the node draws it), else without."""
        self.viewer.watch(draw)
        self.detector.records = []
        run = self.camera.run(count, window)
        self.dropped = self.detector.dropped + self.detector.failed
        return stages_of(self.detector.records, run)

    def close(self) -> None:
        self.context.close()


class OursTwoProcesses:
    """A camera node here (with the bus router), the detector node in a process of its own."""

    def __init__(self, frames: Frames, model: Path, threads: int) -> None:
        with socket.socket() as probe:
            probe.bind(("127.0.0.1", 0))
            endpoint = f"tcp/127.0.0.1:{probe.getsockname()[1]}"
        self.context = Context(BusConfig.router([endpoint]))
        self.peer = subprocess.Popen([sys.executable, "-m", "benchmarks.detector",
                                      "--detector-peer", endpoint,
                                      "--model", str(model), "--threads", str(threads)],
                                     stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
        self.dropped = 0
        self.bus_drops: dict[str, int] = {}
        assert self.peer.stdout is not None
        if self.peer.stdout.readline().strip() != "ready":
            self.close()
            raise RuntimeError("the detector process did not start")
        self.camera = Camera(self.context, frames)
        deadline = time.monotonic() + 20
        while (self.context.shm_reader_count(IMAGE_TOPIC) == 0
               or self.context.shm_reader_count(DEPTH_TOPIC) == 0
               or self.camera.image.subscription_count() == 0) and time.monotonic() < deadline:
            time.sleep(0.01)
        time.sleep(0.3)

    def _ask(self, command: str) -> str:
        assert self.peer.stdin is not None and self.peer.stdout is not None
        self.peer.stdin.write(command + "\n")
        self.peer.stdin.flush()
        return self.peer.stdout.readline()

    def _report(self) -> list[dict[str, float]]:
        answer = json.loads(self._ask("report"))
        self.dropped = int(answer["dropped"])
        self.bus_drops = {str(k): int(v) for k, v in answer["bus"].items()}
        records: list[dict[str, float]] = answer["records"]
        return records

    def run(self, count: int, window: int, *, draw: bool = True) -> Run:
        """As :meth:`OursInProcess.run`, the viewer in the detector's process."""
        if self._ask("draw" if draw else "no-draw").strip() != "ok":
            raise RuntimeError("the detector process does not answer")
        self._report()
        run = self.camera.run(count, window)
        return stages_of(self._report(), run)

    def close(self) -> None:
        if self.peer.stdin is not None:
            self.peer.stdin.close()
        self.peer.wait(10)
        self.context.close()


class PipelineAlone:
    """The detection pipeline alone: what the detector node does between a frame's arrival and
    its messages (preprocess, inference, postprocess, distance, drawing), on the same frames."""

    def __init__(self, frames: Frames, model: Path, threads: int) -> None:
        self.frames = [Frame(0, image, depth=depth) for image, depth in frames]
        detector = Detector.open(model, threads=threads, confidence=THRESHOLD)
        self.pipeline = DetectionPipeline(detector)
        self.tensor = detector.preprocessor(frames[0][0])[0].copy()
        self.paired(20, draw=True)

    def paired(self, pairs: int, *, draw: bool) -> Run:
        """``pairs`` times, one frame through the pipeline and then one bare inference on the
        pipeline's own onnxruntime session (a tensor prepared once). Each pair gives the
        pipeline's overhead over bare inference, its two halves measured within 25 ms of each
        other, in the same state of the machine and of the session's threads."""
        records, bare, spent = [], [], 0.0
        run = Run("", frames=pairs)
        for index in range(pairs):
            started = time.perf_counter()
            result = self.pipeline.process(self.frames[index % len(self.frames)], draw=draw)
            processed = time.perf_counter()
            self.pipeline.detector.backend.run(self.tensor)
            inferred = time.perf_counter()
            spent += processed - started
            bare.append((inferred - processed) * 1e3)
            run.paired.append((processed - started) / (inferred - processed) - 1)
            times = result.times
            records.append({
                "preprocess": times["preprocess"] * 1e3, "inference": times["inference"] * 1e3,
                "postprocess": times["postprocess"] * 1e3,
                "distance": (times["distance"] + times["depth"]) * 1e3,
                "drawing": times["drawing"] * 1e3, "detections": float(len(result.detections))})
        run.paired_bare = bare
        run.fps_rounds = [pairs / spent]
        return stages_of(records, run)


class BareInference:
    """The onnxruntime session alone, on a tensor prepared once."""

    def __init__(self, frames: Frames, model: Path, threads: int) -> None:
        self.backend = OnnxRuntimeBackend(model, threads=threads)
        detector = Detector(self.backend, model_name=model.name)
        self.tensor = detector.preprocessor(frames[0][0])[0].copy()
        self.run(20)

    def run(self, count: int) -> Run:
        samples = []
        for _ in range(count):
            started = time.perf_counter()
            self.backend.run(self.tensor)
            samples.append((time.perf_counter() - started) * 1e3)
        return Run.inference_alone(samples)
