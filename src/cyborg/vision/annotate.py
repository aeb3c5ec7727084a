"""The annotated image: each detection's box with its label, confidence and distance.

    annotated = annotate(frame, detections)   # a new image; the frame is left as it is

The frame is copied with non-temporal stores (:func:`cyborg.bus.stream_copy.stream_copy`):
6 MB written through the caches would push the network's weights and the next frame's data out
of them, which costs more in the next inference than the copy itself. The box outlines are then
drawn on the copy by one compiled loop; the captions are rendered by OpenCV (``putText``,
anti-aliased) on one small atlas of label patches, and each label goes onto the image as one
block copy.

Boxes are outlines ``thickness`` pixels wide centred on the box's edges; each label, white with
black text, sits on top of its box's top-left corner (inside the box when there is no room
above). Labels are drawn over boxes, later detections over earlier ones.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import cv2
import numpy as np
from numba import njit

from cyborg.bus.stream_copy import stream_copy
from cyborg.vision.detector import Detection

BOX_COLOUR = (0, 200, 0)
TEXT_GREY = 0
LABEL_GREY = 255
"""Labels are grey levels (black on white): one channel to render, copied to all three."""
FONT = cv2.FONT_HERSHEY_SIMPLEX


def caption(detection: Detection) -> str:
    """``"person: 0.93 (2.37 m)"``, or ``"person: 0.93 (? m)"`` when the distance is unknown."""
    distance = "?" if math.isnan(detection.distance) else f"{detection.distance:.2f}"
    return f"{detection.label}: {detection.confidence:.2f} ({distance} m)"


@dataclass(frozen=True)
class Overlay:
    """What is drawn on one image: box outlines and label patches, in image pixels."""

    boxes: np.ndarray
    """``N x 4`` int64: the outlines' outer left, top, right and bottom (exclusive) edges."""
    thickness: int
    labels: np.ndarray
    """``N x 5`` int64: left, top, width, height of each label, and its first row in ``atlas``."""
    atlas: np.ndarray
    """The label patches stacked on top of each other, grey levels (``rows x widest`` uint8:
    white background, black text), copied to all three channels when drawn."""

    @classmethod
    def of(cls, width: int, height: int, detections: Sequence[Detection]) -> Overlay:
        """The overlay of ``detections`` on a ``width`` x ``height`` image."""
        scale = max(0.4, min(width, height) / 1000)
        thickness = max(1, round(scale * 2))
        before = thickness // 2  # outline pixels on the outer side of an edge
        boxes: list[tuple[int, int, int, int]] = []
        labels: list[tuple[int, int, int, int, int]] = []
        captions: list[tuple[str, int]] = []
        row = widest = 0
        for detection in detections:
            x1, y1, x2, y2 = (round(value) if math.isfinite(value) else 0
                              for value in detection.box)
            x1, x2, y1, y2 = min(x1, x2), max(x1, x2), min(y1, y2), max(y1, y2)
            boxes.append((x1 - before, y1 - before, x2 - before + thickness,
                          y2 - before + thickness))
            text = caption(detection)
            (text_w, text_h), baseline = cv2.getTextSize(text, FONT, scale, 1)
            label_w, label_h = text_w + 3, text_h + baseline + 3
            top = y1 - label_h + 1 if y1 - label_h + 1 >= 0 else y1
            labels.append((x1, top, label_w, label_h, row))
            captions.append((text, text_h))
            row += label_h
            widest = max(widest, label_w)
        atlas = np.full((row, widest), LABEL_GREY, dtype=np.uint8)
        for (_x, _y, label_w, label_h, first), (text, text_h) in zip(labels, captions,
                                                                     strict=True):
            cv2.putText(atlas[first:first + label_h, :label_w], text, (1, text_h + 1), FONT,
                        scale, TEXT_GREY, 1, cv2.LINE_AA)
        return cls(np.array(boxes, dtype=np.int64).reshape(-1, 4), thickness,
                   np.array(labels, dtype=np.int64).reshape(-1, 5), atlas)


def annotate(image: np.ndarray, detections: Sequence[Detection]) -> np.ndarray:
    """A copy of the BGR ``image`` with the detections drawn on it."""
    return draw_detections(copy_frame(image, np.empty(image.shape, dtype=np.uint8)),
                           detections)


def copy_frame(image: np.ndarray, into: np.ndarray) -> np.ndarray:
    """Copy the BGR ``image`` into ``into`` (writable, C-contiguous, same shape) and return it.

    Non-temporal stores: the copy does not push the network's data out of the CPU's caches; the
    image itself is read into them, for the resize to the network's input that follows.
    """
    _check_bgr(image)
    if into.shape != image.shape or into.dtype != np.uint8 or not into.flags.c_contiguous \
            or not into.flags.writeable:
        raise ValueError(f"copy_frame: into must be a writable C-contiguous uint8 array of "
                         f"shape {image.shape}, not {into.dtype} {into.shape}")
    stream_copy(into, image, keep_source=True)  # the network's input is read from it next
    return into


def draw_detections(drawn: np.ndarray, detections: Sequence[Detection]) -> np.ndarray:
    """Draws the detections on ``drawn`` itself (a writable BGR image) and returns it."""
    if not drawn.flags.writeable:
        raise ValueError("draw_detections: the image is read-only (annotate() draws on a copy)")
    rows = _rows(drawn)
    overlay = Overlay.of(drawn.shape[1], drawn.shape[0], detections)
    _draw_boxes(rows, overlay.boxes, overlay.thickness, np.array(BOX_COLOUR, dtype=np.uint8))
    if overlay.atlas.size:  # the labels: one block copy per label, by numpy
        atlas = cv2.cvtColor(overlay.atlas, cv2.COLOR_GRAY2BGR)
        height, width = drawn.shape[:2]
        image = rows.reshape(drawn.shape)
        for x0, y0, label_w, label_h, first in overlay.labels.tolist():
            left, top = max(x0, 0), max(y0, 0)
            right, bottom = min(x0 + label_w, width), min(y0 + label_h, height)
            if left < right and top < bottom:
                image[top:bottom, left:right] = atlas[first + top - y0:first + bottom - y0,
                                                      left - x0:right - x0]
    if not np.shares_memory(rows, drawn):  # not C-contiguous: drawn on a copy, put it back
        drawn[...] = rows.reshape(drawn.shape)
    return drawn


def _check_bgr(image: np.ndarray) -> None:
    if image.ndim != 3 or image.shape[2] != 3 or image.dtype != np.uint8:
        raise ValueError(f"annotate: expected a BGR uint8 image (H x W x 3), "
                         f"not {image.dtype} {image.shape}")


def _rows(image: np.ndarray) -> np.ndarray:
    """``image`` as ``height x (width * 3)`` bytes (a view when it is contiguous)."""
    _check_bgr(image)
    return np.ascontiguousarray(image).reshape(image.shape[0], image.shape[1] * 3)


@njit("void(uint8[:, ::1], int64[:, ::1], int64, uint8[::1])", cache=True, nogil=True)
def _draw_boxes(target: np.ndarray, boxes: np.ndarray, thickness: int,
                colour: np.ndarray) -> None:  # pragma: no cover - compiled
    """The outlines, box by box and row by row: the top and bottom edges as long runs of
    pixels, the sides as short ones."""
    height, width = target.shape[0], target.shape[1] // 3
    for b in range(boxes.shape[0]):
        left, top = max(boxes[b, 0], 0), max(boxes[b, 1], 0)
        right, bottom = min(boxes[b, 2], width), min(boxes[b, 3], height)
        if left >= right:
            continue
        for y in range(top, bottom):
            row = target[y]
            if y < boxes[b, 1] + thickness or y >= boxes[b, 3] - thickness:  # top or bottom
                spans = ((left, right), (0, 0))
            else:  # the left and right edges
                spans = ((left, min(boxes[b, 0] + thickness, right)),
                         (max(boxes[b, 2] - thickness, left), right))
            for start, end in spans:
                for x in range(start, end):
                    row[3 * x] = colour[0]
                    row[3 * x + 1] = colour[1]
                    row[3 * x + 2] = colour[2]
