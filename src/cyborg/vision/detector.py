"""The detector: an image in, labelled boxes out, with the time each stage took.

    detector = Detector.open("yolox_nano")                      # a name, or a path
    detections = detector.detect(image)                         # BGR uint8, any size
    detector.confidence = 0.6                                   # changeable while running

One :class:`Detector` letterboxes the image (:mod:`~cyborg.vision.letterbox`), runs the network
on a backend (:mod:`~cyborg.vision.backends`), decodes the family's output
(:mod:`~cyborg.vision.layouts`), keeps the classes asked for, and applies class-aware
non-maximum suppression (:mod:`~cyborg.vision.suppression`) — overlapping boxes of one class
collapse to the best one, while a person in front of a car keeps both boxes.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numba import njit

from cyborg.interfaces.detection_messages import corners
from cyborg.vision.backends import Backend, OnnxRuntimeBackend, OpenCvBackend
from cyborg.vision.frames import VisionError, check_image
from cyborg.vision.labels import COCO, label_of, read_labels
from cyborg.vision.layouts import Candidates, Layout, decode, guess_layout, layout_named
from cyborg.vision.letterbox import InputFormat, Letterbox, Preprocessor, to_image
from cyborg.vision.models import find_model
from cyborg.vision.suppression import greedy

FORMATS = {Layout.YOLOX: InputFormat(rgb=False, scale=1.0, centred=False),
           Layout.YOLOV5: InputFormat(rgb=True, scale=1 / 255, centred=True),
           Layout.YOLOV8: InputFormat(rgb=True, scale=1 / 255, centred=True),
           Layout.END2END: InputFormat(rgb=True, scale=1 / 255, centred=True),
           Layout.DARKNET: InputFormat(rgb=True, scale=1 / 255, centred=True)}
"""The input each family was trained on (channel order set per family, never left implicit)."""
DEFAULT_CONFIDENCE = 0.5
"""Detections below this confidence are dropped unless told otherwise."""
DEFAULT_IOU = 0.45
"""Boxes of one class that overlap more than this merge unless told otherwise."""
DEFAULT_BACKEND = OnnxRuntimeBackend.name
"""The runtime of ONNX models unless told otherwise."""


@dataclass(frozen=True)
class Detection:
    """One object: its class, confidence and box in image pixels, and its distance.

    ``distance`` is in metres, NaN when unknown (no depth, or no valid depth in the box);
    ``depth_fraction`` is the share of sampled depth pixels that were valid.
    """

    label: str
    class_id: int
    confidence: float
    box: tuple[float, float, float, float]  # x1, y1, x2, y2
    distance: float = math.nan
    depth_fraction: float = 0.0

    @property
    def corners(self) -> tuple[tuple[float, float], ...]:
        """Top-left, top-right, bottom-right, bottom-left (the 2018 polygon order)."""
        return corners(self.box)


@dataclass
class StageTimes:
    """Seconds spent per stage on the last frame."""

    preprocess: float = 0.0
    inference: float = 0.0
    postprocess: float = 0.0
    extra: dict[str, float] = field(default_factory=dict)


class Detector:
    """A YOLO-family detector on one backend. Thread-compatible, not thread-safe."""

    def __init__(self, backend: Backend, *, layout: Layout | None = None,
                 labels: tuple[str, ...] = COCO, confidence: float = DEFAULT_CONFIDENCE,
                 iou: float = DEFAULT_IOU,
                 classes: frozenset[str] = frozenset(), max_detections: int = 100,
                 model_name: str = "") -> None:
        self.backend = backend
        self.labels = labels
        self.input_hw = backend.input_hw
        self.model_name = model_name or backend.name
        probe = backend.run(np.zeros((1, 3, *self.input_hw), dtype=np.float32))  # warm-up
        self.output_shape = tuple(int(size) for size in probe.shape)
        self.layout = layout or guess_layout(self.output_shape, len(labels), self.input_hw,
                                             model_name)
        self.preprocessor = Preprocessor(self.input_hw, FORMATS[self.layout])
        self.confidence, self.iou = confidence, iou
        self.classes = classes
        self.max_detections = max_detections
        self.times = StageTimes()
        self._decode(probe, 1.1)  # a wrong layout fails here, clearly

    @staticmethod
    def open(model: str | Path, *, backend: str = DEFAULT_BACKEND, family: str | None = None,
             weights: Path | None = None, labels: Path | None = None, threads: int = 0,
             input_size: int | None = None, confidence: float = DEFAULT_CONFIDENCE,
             iou: float = DEFAULT_IOU,
             classes: frozenset[str] = frozenset()) -> Detector:
        """A detector for a model (``.onnx``, or a Darknet ``.cfg`` with ``weights``).

        ``model`` is found as ``cyborg detect --model`` finds it (:func:`~cyborg.vision.models.
        find_model`): a name such as ``"yolox_nano"`` is looked for in ``$CYBORG_MODELS``,
        the shared data's ``models/`` folder and the cache; a :class:`~pathlib.Path`, or a
        string ending in ``.onnx``/``.cfg`` or holding a ``/``, is that file. The layout is
        read from the model's output unless ``family`` names it.
        """
        model = find_model(model)
        names = read_labels(labels) if labels is not None else None
        runner: Backend
        if model.suffix == ".cfg":
            runner = OpenCvBackend(model, weights=weights, threads=threads,
                                   input_size=input_size)
            family = family or "darknet"
        elif backend == "onnxruntime":
            runner = OnnxRuntimeBackend(model, threads=threads, input_size=input_size)
            names = names or _metadata_labels(runner.metadata)
        elif backend == "opencv":
            runner = OpenCvBackend(model, threads=threads, input_size=input_size)
        else:
            raise VisionError(f"unknown backend {backend!r}; known: onnxruntime, opencv")
        return Detector(runner, layout=layout_named(family) if family else None,
                        labels=names or COCO, confidence=confidence, iou=iou,
                        classes=classes, model_name=model.name)

    def detect(self, image: np.ndarray) -> list[Detection]:
        """The objects in one BGR image, best first. Stage times go to :attr:`times`."""
        check_image(image, "image")
        started = time.perf_counter()
        tensor, letterbox = self.preprocessor(image)
        prepared = time.perf_counter()
        output = self.backend.run(tensor)
        inferred = time.perf_counter()
        detections = self.postprocess(output, letterbox)
        self.times = StageTimes(prepared - started, inferred - prepared,
                                time.perf_counter() - inferred)
        return detections

    def postprocess(self, output: np.ndarray, letterbox: Letterbox) -> list[Detection]:
        """Decode, keep the wanted classes, suppress overlaps, map boxes to the image."""
        candidates = self._decode(output, self.confidence)
        if self.classes:
            candidates = self._keep_classes(candidates)
        if not len(candidates):
            return []
        # an end-to-end model has suppressed overlaps itself: only order and limit its boxes
        iou = 1.0 if self.layout is Layout.END2END else self.iou
        chosen = _best_in_image(candidates.boxes, candidates.scores, candidates.class_ids,
                                float(iou), self.max_detections, letterbox.scale,
                                letterbox.offset_x, letterbox.offset_y, letterbox.image_width,
                                letterbox.image_height).tolist()
        return [Detection(label_of(self.labels, int(class_id)), int(class_id), score,
                          (x1, y1, x2, y2)) for x1, y1, x2, y2, score, class_id in chosen]

    def _decode(self, output: np.ndarray, threshold: float) -> Candidates:
        """The layout's candidates; an output that does not fit it is a clear error."""
        try:
            return decode(self.layout, output, self.input_hw, threshold)
        except (IndexError, ValueError) as exc:
            raise VisionError(f"{self.model_name}: output {list(output.shape)} does not fit "
                              f"the {self.layout.value} layout ({exc})") from exc

    def _keep_classes(self, candidates: Candidates) -> Candidates:
        wanted = np.array([label_of(self.labels, int(c)) in self.classes
                           for c in candidates.class_ids], dtype=bool)
        return Candidates(candidates.boxes[wanted], candidates.scores[wanted],
                          candidates.class_ids[wanted])


def _metadata_labels(metadata: dict[str, str]) -> tuple[str, ...] | None:
    """Class names an Ultralytics export stores in its metadata (``{0: 'person', ...}``)."""
    text = metadata.get("names")
    if not text:
        return None
    import ast

    try:
        names = ast.literal_eval(text)
    except (ValueError, SyntaxError):
        return None
    if isinstance(names, dict) and all(isinstance(key, int) for key in names):
        return tuple(str(names[key]) for key in sorted(names))
    return None


@njit("float64[:, :](Array(float32, 2, 'A', readonly=True), Array(float32, 1, 'A', readonly=True), "
      "Array(int32, 1, 'A', readonly=True), float64, int64, float64, float64, float64, float64, "
      "float64)", cache=True, nogil=True)
def _best_in_image(boxes: np.ndarray, scores: np.ndarray, class_ids: np.ndarray, iou: float,
                   limit: int, scale: float, offset_x: float, offset_y: float, width: float,
                   height: float) -> np.ndarray:  # pragma: no cover - compiled
    """Suppression, then the boxes kept in image pixels, best first, as ``N x 6`` rows.

    Each row is ``x1, y1, x2, y2, score, class id``. One compiled call: right after the network
    has run, the numpy calls this replaces (indexing, mapping, three conversions to lists) cost
    several times their warm figure.
    """
    kept = greedy(boxes, scores, class_ids, iou, limit)
    chosen = np.empty((len(kept), 6))
    to_image(boxes, kept, scale, offset_x, offset_y, width, height, chosen)
    for row in range(len(kept)):
        chosen[row, 4], chosen[row, 5] = scores[kept[row]], class_ids[kept[row]]
    return chosen
