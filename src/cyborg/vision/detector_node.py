"""The detector node: camera frames from the bus in; predictions, detections, annotated image out.

Subscribes to a colour image topic and, when given, a depth topic (``32FC1`` metres or
``16UC1`` millimetres) and/or a right-image topic for stereo depth; streams are paired by exact
header stamp and unpaired messages are counted (:attr:`DetectorNode.dropped`). Depth and right
images are waited for only while their topic has a publisher in the bus graph: a camera without
depth (a video file) is detected on the image alone, with distance NaN (unknown). Images that
find no partner for 5 s are detected alone too, and the log says once which topic is silent
(:mod:`~cyborg.vision.camera_inputs`). Publishes, in the node's namespace (the contract is
:mod:`cyborg.interfaces.detector`):

==================  ==================================  ========================================
topic               type                                content
==================  ==================================  ========================================
``predictions``     ``cyborg_msgs/msg/Predictions``     the 2018 message (latched, depth 1)
``detections``      ``vision_msgs/msg/Detection2DArray``  ROS 2's standard message
``detection_image`` ``sensor_msgs/msg/Image``           the image with boxes, labels, distances
==================  ==================================  ========================================

When none of the three has a subscriber the network is not run at all (:attr:`skipped` counts
such frames); the annotated image is drawn only while someone watches it. Runtime parameters:
``confidence_threshold`` (0..1), ``classes`` (labels to keep; empty: all) and
``iou_threshold``; ``cyborg param set /cyborg/detector confidence_threshold 0.7``.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from typing import Any

from cyborg.bus import Node
from cyborg.bus.wire import EntityKind
from cyborg.interfaces.detection_messages import detection_array_message, predictions_message
from cyborg.interfaces.detector import (
    CAMERA_STREAMS,
    CLASSES,
    CONFIDENCE_THRESHOLD,
    DETECTION_IMAGE,
    DETECTIONS,
    IOU_THRESHOLD,
    PREDICTIONS,
)
from cyborg.vision.camera_inputs import CameraInputs
from cyborg.vision.camera_topics import CameraTopics
from cyborg.vision.frames import VisionError
from cyborg.vision.image_messages import bgr_to_image, stamp_ns
from cyborg.vision.pipeline import DetectionPipeline, Result

log = logging.getLogger(__name__)


class DetectorNode:
    """Runs a :class:`DetectionPipeline` on a node, on frames from the bus.

    ``now_ns`` stamps the predictions (wall or simulated time); ``clock`` (monotonic seconds)
    times the ``patience`` (s) granted to a depth publisher that yields no pair. Frames are
    detected on the node's callback thread.
    """

    def __init__(self, node: Node, pipeline: DetectionPipeline, topics: CameraTopics, *,
                 now_ns: Callable[[], int] = time.time_ns,
                 clock: Callable[[], float] = time.monotonic, patience: float = 5.0) -> None:
        self.node, self.pipeline, self.topics = node, pipeline, topics
        self.now_ns = now_ns
        detector = pipeline.detector
        params = node.parameters
        detector.confidence = float(params.declare(
            CONFIDENCE_THRESHOLD, detector.confidence, "detections below this are dropped",
            limits=(0.0, 1.0)))
        detector.iou = float(params.declare(
            IOU_THRESHOLD, detector.iou, "overlap above which boxes of one class merge",
            limits=(0.0, 1.0)))
        detector.classes = frozenset(
            str(name) for name in params.declare(
                CLASSES, [""], "labels to keep (empty: every class)") if name)
        params.on_set(self._check)
        params.on_change(self._apply)
        self.processed = self.skipped = self.failed = 0
        self.last: Result | None = None
        self.predictions = PREDICTIONS.publisher(node)
        self.detections = DETECTIONS.publisher(node)
        self.image = DETECTION_IMAGE.publisher(node)
        self.inputs = CameraInputs(topics, self.publishers, clock=clock, patience=patience,
                                   name=node.fq_name)
        for stream in topics.streams():
            CAMERA_STREAMS[stream].remapped(getattr(topics, stream)).subscription(
                node, self._receiver(stream))

    @property
    def dropped(self) -> int:
        """Messages that never became part of a frame (no partner with their stamp)."""
        return self.inputs.dropped

    def publishers(self, topic: str) -> list[str]:
        """The nodes that publish ``topic`` now, from the bus graph."""
        graph = self.node.context.graph
        return sorted({entity.node_name
                       for entity in graph.endpoints(topic, EntityKind.PUBLISHER)})

    def _check(self, changes: dict[str, Any]) -> None:
        labels = set(self.pipeline.detector.labels)
        unknown = [name for name in changes.get(CLASSES, []) if name and name not in labels]
        if unknown:
            raise ValueError(f"classes: unknown labels {', '.join(map(repr, unknown))}")

    def _apply(self, changes: dict[str, Any]) -> None:
        detector = self.pipeline.detector
        if CONFIDENCE_THRESHOLD in changes:
            detector.confidence = float(changes[CONFIDENCE_THRESHOLD])
        if IOU_THRESHOLD in changes:
            detector.iou = float(changes[IOU_THRESHOLD])
        if CLASSES in changes:
            detector.classes = frozenset(str(name) for name in changes[CLASSES] if name)

    def _receiver(self, stream: str) -> Callable[[Any], None]:
        def receive(message: Any) -> None:
            complete = self.inputs.add(stream, stamp_ns(message.header), message)
            if complete is not None:
                self._on_frame(complete)
        return receive

    def watched(self) -> bool:
        """Whether any output has a subscriber; frames are skipped (and counted) while none has."""
        return any(publisher.subscription_count() > 0
                   for publisher in (self.predictions, self.detections, self.image))

    def _on_frame(self, messages: dict[str, Any]) -> None:
        if not self.watched():
            self.skipped += 1
            return
        image_message = messages["image"]
        try:
            frame = self.topics.frame(messages)
            result = self.pipeline.process(frame, draw=self.image.subscription_count() > 0)
        except VisionError as exc:
            self.failed += 1
            if self.failed == 1 or self.failed % 100 == 0:
                log.warning("%s: frame dropped (%d so far): %s", self.node.fq_name,
                            self.failed, exc)
            return
        self.processed += 1
        self.last = result
        try:
            self.predictions.publish(predictions_message(result.detections,
                                                         image_message.header, self.now_ns()))
            self.detections.publish(detection_array_message(result.detections,
                                                            image_message.header))
            if result.annotated is not None:
                self.image.publish(bgr_to_image(result.annotated, frame.stamp_ns,
                                                frame.frame_id))
        except RuntimeError:
            if not self.node.destroyed:
                raise
            # the node was destroyed while the frame was processed (a stopping launch): the
            # frame's results go nowhere, quietly
