"""The camera and the detector as components: their parameters, defaults, and how they start.

:func:`start_camera` and :func:`start_detector` are the ``camera`` and ``detector`` kinds of
launch files (see :mod:`cyborg.bus.component`) and what ``cyborg up`` runs beside the robot.
Their bus parameters are read-only, but for the detector's thresholds and classes, which
:class:`~cyborg.vision.DetectorNode` lets change while it runs:

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

The values come from where they are defined, :class:`~cyborg.vision.CameraNode`,
:class:`~cyborg.vision.Detector`, :mod:`~cyborg.vision.models` and, for namespaces and topics,
:mod:`cyborg.interfaces.detector`; the constants below name them for the commands that build
specs (``cyborg up``).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path

from cyborg.bus import Context, Node, SimClock
from cyborg.bus.component import NodeSpec
from cyborg.interfaces import detector as contract
from cyborg.vision.camera_node import DEFAULT_FRAME_ID, DEFAULT_RATE, IMAGE_TOPIC, CameraNode
from cyborg.vision.camera_topics import CameraTopics
from cyborg.vision.depth import StereoCalibration, StereoDepth
from cyborg.vision.detector import DEFAULT_BACKEND, Detector
from cyborg.vision.detector_node import DetectorNode
from cyborg.vision.frames import VisionError
from cyborg.vision.models import DEFAULT_MODEL, find_model
from cyborg.vision.pipeline import DetectionPipeline
from cyborg.vision.sources import SourceOptions, anchored, open_source

CAMERA_NAME = "camera"
"""The camera's node name unless told otherwise."""
CAMERA_NAMESPACE = contract.CAMERA_NAMESPACE
"""The camera's namespace unless told otherwise (``/cyborg/camera``)."""
CAMERA_RATE = DEFAULT_RATE
"""Frames per second a camera plays files at unless told otherwise."""
DETECTOR_NAME = "detector"
"""The detector's node name unless told otherwise."""
DETECTOR_NAMESPACE = contract.DETECTOR_NAMESPACE
"""The detector's namespace unless told otherwise (``/cyborg/detector``)."""
MODEL = DEFAULT_MODEL
"""The detector's model unless told otherwise: a name looked for in the model folders."""


def _stamps(node: Node, sim_time: bool) -> Callable[[], int]:
    """Nanosecond stamps from the wall clock, or from ``/clock`` under ``use_sim_time``."""
    if not sim_time:
        return time.time_ns
    clock = SimClock(node)
    return lambda: round(clock.now() * 1e9)


class RunningCamera:
    """A started camera: its node, playing ``source``."""

    def __init__(self, camera: CameraNode, source: str) -> None:
        self.camera, self.source = camera, source

    def describe(self) -> str:
        """What it plays, how fast, and on which topics."""
        node = self.camera.node
        return (f"camera       {node.fq_name}: {self.source} at {self.camera.rate:g} Hz on "
                f"{node.namespace}/{IMAGE_TOPIC} (+ right, depth when the source has them)")

    def stop(self) -> None:
        """Stops playing and leaves the bus."""
        self.camera.stop()
        self.camera.node.destroy()


def start_camera(context: Context, spec: NodeSpec) -> RunningCamera:
    """Starts a camera from ``spec``; a source that cannot be opened refuses it."""
    node = Node(spec.name, spec.namespace, context=context, parameters=spec.parameters)
    try:
        params = node.parameters
        source = str(params.declare("source", "", "what to play", read_only=True))
        if not source:
            raise spec.error("the camera needs a `source` parameter (a file, folder, video, "
                             "bag, camera:N or sample:motorcycle)")
        rate = float(params.declare("rate", CAMERA_RATE, "frames per second", read_only=True))
        loop = bool(params.declare("loop", True, "start again at the end", read_only=True))
        sbs = bool(params.declare("side_by_side", False, "left|right frames", read_only=True))
        depth = str(params.declare("depth", "", "depth map file of an image", read_only=True))
        right = str(params.declare("right", "", "right image file", read_only=True))
        image_topic = str(params.declare("image_topic", "", "bag image topic", read_only=True))
        depth_topic = str(params.declare("depth_topic", "", "bag depth topic", read_only=True))
        frame_id = str(params.declare("frame_id", DEFAULT_FRAME_ID, "frame of the images",
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
                            loop=loop, frame_id=frame_id, now_ns=_stamps(node, sim_time))
        camera.start()
    except BaseException:
        node.destroy()
        raise
    return RunningCamera(camera, source)


class RunningDetector:
    """A started detector: its node, and the model it runs."""

    def __init__(self, detector: DetectorNode, model: Path) -> None:
        self.detector, self.model = detector, model

    def describe(self) -> str:
        """The model and its runtime, the topics it reads, and those it publishes."""
        node, detector = self.detector.node, self.detector.pipeline.detector
        inputs = ", ".join(topic for topic in (self.detector.topics.image,
                                               self.detector.topics.depth,
                                               self.detector.topics.right) if topic)
        return (f"detector     {node.fq_name}: {self.model.name} ({detector.layout.value}, "
                f"{detector.backend.name}) on {inputs}; publishes {node.namespace}/predictions,"
                f" .../detections, .../detection_image while subscribed")

    def stop(self) -> None:
        """Leaves the bus."""
        self.detector.node.destroy()


def start_detector(context: Context, spec: NodeSpec) -> RunningDetector:
    """Starts a detector from ``spec``; a model that cannot be found or run refuses it."""
    node = Node(spec.name, spec.namespace, context=context, parameters=spec.parameters)
    try:
        params = node.parameters

        def fixed(name: str, default: object, description: str) -> object:
            return params.declare(name, default, description, read_only=True)

        model_name = str(fixed("model", MODEL, "model file or name"))
        family = str(fixed("family", "", "detector family (default: from the model)"))
        backend = str(fixed("backend", DEFAULT_BACKEND, "onnxruntime or opencv"))
        weights = str(fixed("weights", "", "Darknet weights file"))
        labels = str(fixed("labels", "", "label file (default: COCO)"))
        threads = int(fixed("threads", 0, "inference threads (0: auto)"))  # type: ignore[call-overload]
        input_size = int(fixed("input_size", 0, "input size of dynamic models"))  # type: ignore[call-overload]
        image_topic = str(fixed("image_topic", contract.DEFAULT_IMAGE_TOPIC, "images"))
        depth_topic = str(fixed("depth_topic", contract.DEFAULT_DEPTH_TOPIC,
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
                                     now_ns=_stamps(node, sim_time))
    except BaseException:
        node.destroy()
        raise
    return RunningDetector(detector_node, model)
