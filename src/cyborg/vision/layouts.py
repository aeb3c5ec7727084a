"""What a detector network's output means, per YOLO family, and how to decode it.

Every layout is decoded to candidates in the *network input's* pixels: boxes as
``x1, y1, x2, y2``, a score and a class id per box, before non-maximum suppression.

==============  =====================  ===========================================================
layout          output (80 classes)    meaning
==============  =====================  ===========================================================
``yolox``       ``1 x N x 85``         raw YOLOX head: ``(xy + grid) * stride``,
                                       ``exp(wh) * stride`` over strides 8, 16, 32; objectness,
                                       then class scores; score = obj x cls
``yolov5``      ``1 x N x 85``         YOLOv5/v6/v7: centre x, y, w, h in pixels, objectness,
                                       class probabilities; score = obj x cls
``yolov8``      ``1 x 84 x N``         YOLOv8/YOLO11: transposed; 4 box + class scores, no
                                       objectness
``end2end``     ``1 x K x 6``          YOLOv10 / YOLO26: x1, y1, x2, y2, score, class; NMS-free
``darknet``     ``M x 85`` (per head)  OpenCV's Darknet importer: normalised centre x, y, w, h,
                                       objectness, class columns already obj x cls
==============  =====================  ===========================================================

:func:`guess_layout` names the layout from the output's shape where the shape decides it (YOLOX's
raw output is shaped like YOLOv5's, so it needs the model's name or an explicit layout).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import Enum

import numpy as np
from numba import njit

from cyborg.vision.frames import VisionError


class Layout(Enum):
    """How a network's output is laid out; see the module docstring's table."""

    YOLOX = "yolox"
    YOLOV5 = "yolov5"
    YOLOV8 = "yolov8"
    END2END = "end2end"
    DARKNET = "darknet"


LAYOUT_ALIASES = {"yolox": Layout.YOLOX, "yolov5": Layout.YOLOV5, "yolov6": Layout.YOLOV5,
                  "yolov7": Layout.YOLOV5, "yolov8": Layout.YOLOV8, "yolov9": Layout.YOLOV8,
                  "yolo11": Layout.YOLOV8, "yolov11": Layout.YOLOV8,
                  "yolov10": Layout.END2END, "yolo26": Layout.END2END,
                  "end2end": Layout.END2END, "darknet": Layout.DARKNET}
"""Family names a user may give (``--family``), and the layout each one exports."""


def layout_named(name: str) -> Layout:
    """The layout of the family ``name`` (any case); :class:`VisionError` for an unknown one."""
    try:
        return LAYOUT_ALIASES[name.lower()]
    except KeyError:
        raise VisionError(f"unknown detector family {name!r}; known: "
                          f"{', '.join(sorted(LAYOUT_ALIASES))}") from None


@dataclass(frozen=True)
class Candidates:
    """Boxes before non-maximum suppression, in network-input pixels."""

    boxes: np.ndarray      # float32, n x 4: x1, y1, x2, y2
    scores: np.ndarray     # float32, n
    class_ids: np.ndarray  # int32, n

    def __len__(self) -> int:
        return len(self.scores)

    @staticmethod
    def empty() -> Candidates:
        """No candidates: arrays of length 0 of the right types."""
        return Candidates(np.zeros((0, 4), np.float32), np.zeros(0, np.float32),
                          np.zeros(0, np.int32))


def grid_points(input_hw: tuple[int, int], strides: tuple[int, ...] = (8, 16, 32)) -> int:
    """How many anchor points an anchor-free head has for this input size (3549 at 416)."""
    height, width = input_hw
    return sum((height // stride) * (width // stride) for stride in strides)


def guess_layout(shape: tuple[int, ...], num_classes: int | None, input_hw: tuple[int, int],
                 model_name: str = "") -> Layout:
    """The layout an output of ``shape`` has, or a :class:`VisionError` saying why not."""
    where = f"{model_name}: " if model_name else ""
    if "yolox" in model_name.lower():
        return Layout.YOLOX
    if len(shape) != 3 or shape[0] != 1:
        raise VisionError(f"{where}unknown output layout {list(shape)}: expected 1 x A x B "
                          "(YOLOv5/v7, YOLOv8/11, YOLOv10 or YOLOX); pass the family explicitly")
    rows, columns = int(shape[1]), int(shape[2])
    if columns == 6 and rows <= 1000:
        return Layout.END2END
    if rows < columns:
        if num_classes is not None and rows - 4 != num_classes:
            raise VisionError(f"{where}output {list(shape)} looks like YOLOv8 (4 + classes by "
                              f"anchors), but {rows - 4} classes do not match the "
                              f"{num_classes} labels")
        return Layout.YOLOV8
    if num_classes is None or columns - 5 == num_classes:
        if rows == 3 * grid_points(input_hw):
            return Layout.YOLOV5
        if rows == grid_points(input_hw):
            raise VisionError(f"{where}output {list(shape)} is shaped like both a raw YOLOX head "
                              "and a decoded YOLOv6 one; pass the family (yolox or yolov6)")
        return Layout.YOLOV5
    raise VisionError(f"{where}unknown output layout {list(shape)} for {num_classes} classes; "
                      "pass the family explicitly (yolox, yolov5, yolov8, yolov10, darknet)")


def decode(layout: Layout, output: np.ndarray, input_hw: tuple[int, int],
           threshold: float) -> Candidates:
    """Candidates scoring at least ``threshold`` from one image's raw output."""
    rows = output.reshape(-1, output.shape[-1]) if layout is not Layout.YOLOV8 \
        else output.reshape(output.shape[-2], output.shape[-1]).T
    if layout is Layout.END2END:
        keep = rows[:, 4] >= threshold
        chosen = rows[keep]
        return Candidates(chosen[:, :4].astype(np.float32), chosen[:, 4].astype(np.float32),
                          chosen[:, 5].astype(np.int32))
    if layout is Layout.YOLOV8:
        # reduce over classes along the output's own rows (contiguous), and look for the class
        # only where the best score passes: 8400 x 80 at 640, 0.76 -> 0.1 ms
        table = rows.T  # (4 + classes) x anchors, as the network wrote it
        scores = table[4:].max(axis=0)
        passing = np.flatnonzero(scores >= threshold)
        class_ids = table[4:, passing].argmax(axis=0)
        return _from_centres(table[:4, passing].T, scores[passing], class_ids)
    if layout is Layout.DARKNET:
        keep = rows[:, 4] >= threshold  # class columns are already obj x cls
        chosen = rows[keep]
        scale = np.array([input_hw[1], input_hw[0]] * 2, dtype=np.float32)
        class_ids = chosen[:, 5:].argmax(axis=1)
        scores = chosen[np.arange(len(chosen)), 5 + class_ids]
        above = scores >= threshold
        return _from_centres(chosen[above, :4] * scale, scores[above], class_ids[above])
    if rows.shape[1] < 6:
        raise ValueError(f"{rows.shape[1]} columns: expected 4 box, objectness and classes")
    if layout is Layout.YOLOX:
        cells, strides = yolox_grid(input_hw)
        if len(cells) != len(rows):
            raise VisionError(f"YOLOX output has {len(rows)} anchor points, but a "
                              f"{input_hw[1]}x{input_hw[0]} input has {len(cells)}: is this a "
                              "YOLOX model with its head left raw?")
    else:
        cells, strides = _NO_GRID
    boxes, scores, class_ids = _decode_with_objectness(
        rows.astype(np.float32, copy=False), cells, strides[:, 0], layout is Layout.YOLOX,
        float(threshold))
    return Candidates(boxes, scores, class_ids)


_GRIDS: dict[tuple[int, int], tuple[np.ndarray, np.ndarray]] = {}


def yolox_grid(input_hw: tuple[int, int]) -> tuple[np.ndarray, np.ndarray]:
    """Per anchor point: its grid cell (x, y) and its stride."""
    if input_hw not in _GRIDS:
        cells, strides = [], []
        for stride in (8, 16, 32):
            rows, columns = input_hw[0] // stride, input_hw[1] // stride
            ys, xs = np.mgrid[0:rows, 0:columns]
            cells.append(np.stack([xs.ravel(), ys.ravel()], axis=1))
            strides.append(np.full(rows * columns, stride))
        _GRIDS[input_hw] = (np.concatenate(cells).astype(np.float32),
                            np.concatenate(strides).astype(np.float32)[:, None])
    return _GRIDS[input_hw]


_NO_GRID = (np.zeros((0, 2), np.float32), np.zeros((0, 1), np.float32))


@njit("Tuple((float32[:, :], float32[:], int32[:]))(Array(float32, 2, 'A', readonly=True), "
      "Array(float32, 2, 'A', readonly=True), Array(float32, 1, 'A', readonly=True), boolean, "
      "float64)", cache=True, nogil=True)
def _decode_with_objectness(rows: np.ndarray, cells: np.ndarray, strides: np.ndarray,
                            raw_grid: bool, threshold: float
                            ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:  # pragma: no cover
    """YOLOX / YOLOv5 rows (``x, y, w, h, objectness, classes...``) to candidates, in one pass.

    Objectness is looked at first: a row whose objectness is below the threshold can never
    pass it (the score is objectness x class probability). The class is the first best one.
    ``raw_grid``: YOLOX's raw head, ``(xy + cell) * stride`` and ``exp(wh) * stride``; else
    the row's box is a centre and size in input pixels already.
    """
    count, columns = rows.shape
    boxes = np.empty((count, 4), dtype=np.float32)
    scores = np.empty(count, dtype=np.float32)
    class_ids = np.empty(count, dtype=np.int32)
    kept = 0
    for i in range(count):
        objectness = rows[i, 4]
        if not objectness >= threshold:
            continue
        best = 5
        for column in range(6, columns):
            if rows[i, column] > rows[i, best]:
                best = column
        score = objectness * rows[i, best]
        if not score >= threshold:
            continue
        if raw_grid:
            stride = strides[i]
            x, y = (rows[i, 0] + cells[i, 0]) * stride, (rows[i, 1] + cells[i, 1]) * stride
            w, h = math.exp(rows[i, 2]) * stride, math.exp(rows[i, 3]) * stride
        else:
            x, y, w, h = rows[i, 0], rows[i, 1], rows[i, 2], rows[i, 3]
        boxes[kept, 0], boxes[kept, 1] = x - w / 2, y - h / 2
        boxes[kept, 2], boxes[kept, 3] = x + w / 2, y + h / 2
        scores[kept] = score
        class_ids[kept] = best - 5
        kept += 1
    return boxes[:kept], scores[:kept], class_ids[:kept]


def _from_centres(centres: np.ndarray, scores: np.ndarray, class_ids: np.ndarray) -> Candidates:
    half = centres[:, 2:4] / 2
    boxes = np.concatenate([centres[:, :2] - half, centres[:, :2] + half], axis=1)
    return Candidates(boxes.astype(np.float32), scores.astype(np.float32),
                      class_ids.astype(np.int32))
