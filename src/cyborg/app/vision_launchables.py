"""The launch kinds of the vision stack: ``camera`` and ``detector``.

==============  ================================================================================
kind            parameters (default)
==============  ================================================================================
``camera``      ``source`` (required: a file, folder, video, bag, ``camera:N`` or
                ``sample:motorcycle``), ``rate`` (15 Hz), ``loop`` (true), ``side_by_side``,
                ``depth``/``right`` (files for a single image), ``image_topic``/``depth_topic``
                (bags), ``frame_id`` (camera_left), ``use_sim_time`` (false: wall-clock stamps)
``detector``    ``model`` (yolox_nano: a path or a name in the model folders), ``family``,
                ``backend`` (onnxruntime), ``threads`` (0: auto), ``input_size``, ``labels``,
                ``weights`` (Darknet), ``confidence_threshold`` (0.5), ``iou_threshold`` (0.45),
                ``classes`` (all), ``image_topic`` (/cyborg/camera/left/image_raw),
                ``depth_topic`` (/cyborg/camera/depth/depth_registered; "" for none;
                waited for only while it has a publisher, else distances are NaN),
                ``right_topic`` (""), ``focal``/``baseline``/``doffs`` (stereo depth),
                ``use_sim_time``
==============  ================================================================================
"""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path

from cyborg.app.node_spec import NodeSpec
from cyborg.bus import Context, Node, SimClock
from cyborg.vision import (
    CameraNode,
    CameraTopics,
    DetectionPipeline,
    Detector,
    DetectorNode,
    SourceOptions,
    StereoCalibration,
    StereoDepth,
    VisionError,
    open_source,
)
from cyborg.vision.camera_node import DEPTH_TOPIC, IMAGE_TOPIC
from cyborg.vision.models import DEFAULT_MODEL, find_model
from cyborg.vision.sources import anchored

DEFAULT_CAMERA = "/cyborg/camera"


def _clock(node: Node, sim_time: bool) -> Callable[[], int]:
    if not sim_time:
        return time.time_ns
    clock = SimClock(node)
    return lambda: round(clock.now() * 1e9)


class RunningCamera:
    def __init__(self, camera: CameraNode, source: str) -> None:
        self.camera, self.source = camera, source

    def describe(self) -> str:
        node = self.camera.node
        return (f"camera       {node.fq_name}: {self.source} at {self.camera.rate:g} Hz on "
                f"{node.namespace}/{IMAGE_TOPIC} (+ right, depth when the source has them)")

    def stop(self) -> None:
        self.camera.stop()
        self.camera.node.destroy()


def start_camera(context: Context, spec: NodeSpec) -> RunningCamera:
    node = Node(spec.name, spec.namespace, context=context, parameters=spec.parameters)
    try:
        params = node.parameters
        source = str(params.declare("source", "", "what to play", read_only=True))
        if not source:
            raise spec.error("the camera needs a `source` parameter (a file, folder, video, "
                             "bag, camera:N or sample:motorcycle)")
        rate = float(params.declare("rate", 15.0, "frames per second", read_only=True))
        loop = bool(params.declare("loop", True, "start again at the end", read_only=True))
        sbs = bool(params.declare("side_by_side", False, "left|right frames", read_only=True))
        depth = str(params.declare("depth", "", "depth map file of an image", read_only=True))
        right = str(params.declare("right", "", "right image file", read_only=True))
        image_topic = str(params.declare("image_topic", "", "bag image topic", read_only=True))
        depth_topic = str(params.declare("depth_topic", "", "bag depth topic", read_only=True))
        frame_id = str(params.declare("frame_id", "camera_left", "frame of the images",
                                      read_only=True))
        sim_time = bool(params.declare("use_sim_time", False, "stamp with /clock",
                                       read_only=True))
        spec_source = anchored(source, spec.base)
        options = SourceOptions(right=spec.path(right) if right else None,
                                depth=spec.path(depth) if depth else None, side_by_side=sbs,
                                image_topic=image_topic or None,
                                depth_topic=depth_topic or None)
        try:
            open_source(spec_source, options).close()  # a bad source fails the launch now
        except VisionError as exc:
            raise spec.error(str(exc)) from exc
        camera = CameraNode(node, lambda: open_source(spec_source, options), rate=rate,
                            loop=loop, frame_id=frame_id, now_ns=_clock(node, sim_time))
        camera.start()
    except BaseException:
        node.destroy()
        raise
    return RunningCamera(camera, source)


class RunningDetector:
    def __init__(self, detector: DetectorNode, model: Path) -> None:
        self.detector, self.model = detector, model

    def describe(self) -> str:
        node, detector = self.detector.node, self.detector.pipeline.detector
        inputs = ", ".join(topic for topic in (self.detector.topics.image,
                                               self.detector.topics.depth,
                                               self.detector.topics.right) if topic)
        return (f"detector     {node.fq_name}: {self.model.name} ({detector.layout.value}, "
                f"{detector.backend.name}) on {inputs}; publishes {node.namespace}/predictions,"
                f" .../detections, .../detection_image while subscribed")

    def stop(self) -> None:
        self.detector.node.destroy()


def start_detector(context: Context, spec: NodeSpec) -> RunningDetector:
    node = Node(spec.name, spec.namespace, context=context, parameters=spec.parameters)
    try:
        params = node.parameters

        def fixed(name: str, default: object, description: str) -> object:
            return params.declare(name, default, description, read_only=True)

        model_name = str(fixed("model", DEFAULT_MODEL, "model file or name"))
        family = str(fixed("family", "", "detector family (default: from the model)"))
        backend = str(fixed("backend", "onnxruntime", "onnxruntime or opencv"))
        weights = str(fixed("weights", "", "Darknet weights file"))
        labels = str(fixed("labels", "", "label file (default: COCO)"))
        threads = int(fixed("threads", 0, "inference threads (0: auto)"))  # type: ignore[call-overload]
        input_size = int(fixed("input_size", 0, "input size of dynamic models"))  # type: ignore[call-overload]
        image_topic = str(fixed("image_topic", f"{DEFAULT_CAMERA}/{IMAGE_TOPIC}", "images"))
        depth_topic = str(fixed("depth_topic", f"{DEFAULT_CAMERA}/{DEPTH_TOPIC}",
                                "depth maps (empty: none)"))
        right_topic = str(fixed("right_topic", "", "right images for stereo depth"))
        focal = float(fixed("focal", 0.0, "stereo focal length, px"))  # type: ignore[arg-type]
        baseline = float(fixed("baseline", 0.0, "stereo baseline, m"))  # type: ignore[arg-type]
        doffs = float(fixed("doffs", 0.0, "stereo principal point offset, px"))  # type: ignore[arg-type]
        sim_time = bool(fixed("use_sim_time", False, "stamp with /clock"))
        try:
            model = find_model(model_name if not model_name.endswith((".onnx", ".cfg"))
                               else str(spec.path(model_name)))
            detector = Detector.open(
                model, backend=backend, family=family or None,
                weights=spec.path(weights) if weights else None,
                labels=spec.path(labels) if labels else None, threads=threads,
                input_size=input_size or None)
            stereo = StereoDepth(StereoCalibration(focal, baseline, doffs)) \
                if right_topic and focal and baseline else None
        except VisionError as exc:
            raise spec.error(str(exc)) from exc
        if right_topic and stereo is None:
            raise spec.error("right_topic needs focal and baseline for depth from stereo")
        detector_node = DetectorNode(node, DetectionPipeline(detector, stereo=stereo),
                                     CameraTopics(image_topic, depth_topic, right_topic),
                                     now_ns=_clock(node, sim_time))
    except BaseException:
        node.destroy()
        raise
    return RunningDetector(detector_node, model)
