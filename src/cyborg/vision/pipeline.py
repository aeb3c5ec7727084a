"""Frame in, detections with distances out: the detector plus depth, timed per stage.

    pipeline = DetectionPipeline(Detector.open(model), stereo=StereoDepth(calibration))
    result = pipeline.process(frame)      # frame: image + depth map, or a stereo pair
    for detection in result.detections:
        print(detection.label, detection.distance)

Depth comes from the frame's depth map when it has one, else from its stereo pair when the
pipeline has a :class:`~cyborg.vision.depth.StereoDepth`, else distances are NaN (unknown).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from cyborg.vision.annotate import copy_frame, draw_detections
from cyborg.vision.canvases import Canvases
from cyborg.vision.depth import StereoDepth
from cyborg.vision.detector import Detection, Detector
from cyborg.vision.distance import SAMPLES, box_distances
from cyborg.vision.frames import Frame

STAGES = ("depth", "preprocess", "inference", "postprocess", "distance", "drawing")


@dataclass
class Result:
    """The detections of one frame, its depth map (if any) and seconds per stage."""

    frame: Frame
    detections: list[Detection]
    depth: np.ndarray | None
    times: dict[str, float] = field(default_factory=dict)
    annotated: np.ndarray | None = None


class DetectionPipeline:
    """A detector, depth for distances, and the annotated image when asked for."""

    def __init__(self, detector: Detector, *, stereo: StereoDepth | None = None,
                 inner: float = 0.5, samples: int = SAMPLES) -> None:
        self.detector, self.stereo = detector, stereo
        self.inner, self.samples = inner, samples
        self.canvases = Canvases()

    def depth_of(self, frame: Frame) -> np.ndarray | None:
        """The frame's depth map (m): its own, else from its stereo pair; None without either."""
        if frame.depth is not None:
            return frame.depth
        if frame.right is not None and self.stereo is not None:
            return self.stereo.depth(frame.left, frame.right)
        return None

    def process(self, frame: Frame, *, draw: bool = False) -> Result:
        """Detections with distances for one frame; ``draw``: also the annotated image."""
        started = time.perf_counter()
        # The annotated image is drawn on a copy (the frame itself may be shared, e.g. with
        # another subscriber), made first: the copy's reads bring the frame into the cache for
        # the network's input, and its non-temporal writes leave the cache alone.
        canvas = copy_frame(frame.left, self.canvases.take(frame.left.shape)) if draw else None
        copied = time.perf_counter()
        depth = self.depth_of(frame)
        depth_done = time.perf_counter()
        detections = self.detector.detect(frame.left)
        detected = time.perf_counter()
        if depth is not None and detections:
            measured = box_distances(depth, np.array([d.box for d in detections]),
                                     inner=self.inner, samples=self.samples)
            detections = [Detection(d.label, d.class_id, d.confidence, d.box, median, share)
                          for d, (median, share) in zip(detections, measured.tolist(),
                                                        strict=True)]
        distanced = time.perf_counter()
        if canvas is not None:
            draw_detections(canvas, detections)
        drawn = time.perf_counter()
        stage = self.detector.times
        return Result(frame, detections, depth, {
            "depth": depth_done - copied, "preprocess": stage.preprocess,
            "inference": stage.inference, "postprocess": stage.postprocess,
            "distance": distanced - detected,
            "drawing": (copied - started) + (drawn - distanced)}, canvas)
