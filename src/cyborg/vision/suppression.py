"""Class-aware non-maximum suppression: overlapping boxes of one class collapse to the best one.

A detector proposes several boxes around each object (neighbouring anchor points all see it).
Greedy suppression keeps the highest-scoring box, drops every box of the *same class* that
overlaps it by more than ``iou`` (intersection over union), and repeats with the next box left.
Boxes of different classes never compete, so a person standing in front of a car keeps both.
The 2018 node had no suppression and reported every proposal.

    kept = suppress(boxes, scores, class_ids, iou=0.45, limit=100)   # indices, best first

The semantics are OpenCV's ``cv2.dnn.NMSBoxesBatched`` (boxes taken in order of score, ties in
input order; a box is kept when its IoU with every kept box of its class is at most ``iou``);
the tests use OpenCV as the oracle. It is compiled rather than called through OpenCV because it
runs right after the network, when the CPU's caches hold the network's data instead of
Python's and numpy's: the binding's argument conversion then costs about 0.1 ms per frame on
its own, the whole compiled pass a few microseconds.
"""

from __future__ import annotations

import numpy as np
from numba import njit


def suppress(boxes: np.ndarray, scores: np.ndarray, class_ids: np.ndarray, *, iou: float,
             limit: int = 100) -> np.ndarray:
    """Indices of the boxes kept (``x1, y1, x2, y2``), best score first, at most ``limit``."""
    if not len(boxes) == len(scores) == len(class_ids):
        raise ValueError(f"{len(boxes)} boxes, {len(scores)} scores and {len(class_ids)} "
                         "class ids: one of each per box")
    if limit < 0:
        raise ValueError(f"limit must not be negative, not {limit}")
    kept: np.ndarray = greedy(np.asarray(boxes, np.float32).reshape(-1, 4),
                              np.asarray(scores, np.float32),
                              np.asarray(class_ids, np.int32), float(iou), int(limit))
    return kept


@njit("int64[:](Array(float32, 2, 'A', readonly=True), Array(float32, 1, 'A', readonly=True), "
      "Array(int32, 1, 'A', readonly=True), float64, int64)", cache=True, nogil=True)
def greedy(boxes: np.ndarray, scores: np.ndarray, class_ids: np.ndarray, iou: float,
           limit: int) -> np.ndarray:  # pragma: no cover - compiled
    """:func:`suppress` without its checks, for compiled callers."""
    order = np.argsort(-scores, kind="mergesort")  # stable: ties keep their input order
    kept = np.empty(min(limit, len(order)), dtype=np.int64)
    count = 0
    for candidate in order:
        if count == len(kept):
            break
        x1, y1, x2, y2 = boxes[candidate, 0], boxes[candidate, 1], boxes[candidate, 2], \
            boxes[candidate, 3]
        area = max(x2 - x1, 0.0) * max(y2 - y1, 0.0)
        keep = True
        for k in range(count):
            other = kept[k]
            if class_ids[other] != class_ids[candidate]:
                continue
            ox1, oy1, ox2, oy2 = boxes[other, 0], boxes[other, 1], boxes[other, 2], \
                boxes[other, 3]
            width = min(x2, ox2) - max(x1, ox1)
            height = min(y2, oy2) - max(y1, oy1)
            if width <= 0 or height <= 0:
                continue
            overlap = width * height
            union = area + max(ox2 - ox1, 0.0) * max(oy2 - oy1, 0.0) - overlap
            if union > 0 and overlap / union > iou:
                keep = False
                break
        if keep:
            kept[count] = candidate
            count += 1
    return kept[:count]
