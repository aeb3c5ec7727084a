"""The annotated image: each detection's box with its label, confidence and distance.

    annotated = annotate(frame, detections)   # a new image; the frame is left as it is

The frame is copied with non-temporal stores (:func:`cyborg.bus.stream_copy.stream_copy`):
6 MB written through the caches would push the network's weights and the next frame's data out
of them, which costs more in the next inference than the copy itself. Then one compiled loop
lays out and draws everything on the copy: the box outlines, and each label with its caption
composed from characters OpenCV rendered once (:mod:`cyborg.vision.glyphs`). Drawing runs right
after the network, when Python's and OpenCV's code and data are out of the CPU's caches; one
call instead of a few per detection is most of what makes it cheap.

Boxes are outlines ``thickness`` pixels wide centred on the box's edges; each label, white with
black text, sits on top of its box's top-left corner (inside the box when there is no room
above). Labels are drawn over boxes, later detections over earlier ones.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numba import njit

from cyborg.bus.stream_copy import stream_copy
from cyborg.vision.detector import Detection
from cyborg.vision.glyphs import FIRST, FONT, GlyphFont, encode

__all__ = ["BOX_COLOUR", "FONT", "LABEL_GREY", "Overlay", "annotate", "caption", "copy_frame",
           "draw_detections"]

BOX_COLOUR = (0, 200, 0)
LABEL_GREY = 255
"""The labels' background; their text is black, anti-aliased."""
_COLOUR = np.array(BOX_COLOUR, dtype=np.uint8)
_LIMIT = float(1 << 40)
"""Box coordinates are clamped to +-this many pixels before they become integers."""


def caption(detection: Detection) -> str:
    """``"person: 0.93 (2.37 m)"``, or ``"person: 0.93 (? m)"`` when the distance is unknown."""
    distance = "?" if math.isnan(detection.distance) else f"{detection.distance:.2f}"
    return f"{detection.label}: {detection.confidence:.2f} ({distance} m)"


def line_sizes(width: int, height: int) -> tuple[float, int]:
    """The font scale and the outlines' thickness for a ``width`` x ``height`` image."""
    scale = max(0.4, min(width, height) / 1000)
    return scale, max(1, round(scale * 2))


@dataclass(frozen=True)
class Overlay:
    """What is drawn on one image: box outlines and labels, in image pixels."""

    boxes: np.ndarray
    """``N x 4`` int64: the outlines' outer left, top, right and bottom (exclusive) edges."""
    thickness: int
    labels: np.ndarray
    """``N x 4`` int64: left, top, width and height of each label."""
    codes: np.ndarray
    """The captions' characters, one after another (:func:`cyborg.vision.glyphs.encode`)."""
    ends: np.ndarray
    """Where each caption ends in ``codes``."""
    font: GlyphFont

    @classmethod
    def of(cls, width: int, height: int, detections: Sequence[Detection]) -> Overlay:
        """The overlay of ``detections`` on a ``width`` x ``height`` image."""
        boxes, thickness, codes, ends, font = _inputs(width, height, detections)
        outlines = np.empty((len(detections), 4), dtype=np.int64)
        labels = np.empty((len(detections), 4), dtype=np.int64)
        _layout(boxes, thickness, codes, ends, font.advances, font.descents, font.height,
                outlines, labels)
        return cls(outlines, thickness, labels, codes, ends, font)

    def caption_codes(self, index: int) -> np.ndarray:
        """The characters of detection ``index``'s caption."""
        return self.codes[self.ends[index - 1] if index else 0:self.ends[index]]


def _inputs(width: int, height: int, detections: Sequence[Detection]
            ) -> tuple[np.ndarray, int, np.ndarray, np.ndarray, GlyphFont]:
    """What the compiled layout takes: boxes, thickness, captions and the font."""
    scale, thickness = line_sizes(width, height)
    codes, ends = encode([caption(detection) for detection in detections])
    boxes = np.array([detection.box for detection in detections],
                     dtype=np.float64).reshape(-1, 4)
    return boxes, thickness, codes, ends, GlyphFont.at(scale)


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
    boxes, thickness, codes, ends, font = _inputs(drawn.shape[1], drawn.shape[0], detections)
    _draw(rows, boxes, thickness, _COLOUR, codes, ends, font.cells, font.ink, font.advances,
          font.descents, font.height, font.pen_x, font.pen_y)
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


@njit("void(float64[:, ::1], int64, Array(uint8, 1, 'C', readonly=True), int64[::1], "
      "float64[::1], int64[::1], int64, int64[:, ::1], int64[:, ::1])", cache=True, nogil=True)
def _layout(boxes: np.ndarray, thickness: int, codes: np.ndarray, ends: np.ndarray,
            advances: np.ndarray, descents: np.ndarray, height: int, outlines: np.ndarray,
            labels: np.ndarray) -> None:  # pragma: no cover - compiled
    """Fills ``outlines`` and ``labels`` (see :class:`Overlay`) for ``N x 4`` float boxes."""
    before = thickness // 2  # outline pixels on the outer side of an edge
    start = 0
    for b in range(boxes.shape[0]):
        edges = np.zeros(4, dtype=np.int64)  # a box with a NaN or infinite edge: at 0
        for k in range(4):
            if math.isfinite(boxes[b, k]):
                edges[k] = int(np.rint(min(max(boxes[b, k], -_LIMIT), _LIMIT)))
        x1, x2 = min(edges[0], edges[2]), max(edges[0], edges[2])
        y1, y2 = min(edges[1], edges[3]), max(edges[1], edges[3])
        outlines[b, 0], outlines[b, 1] = x1 - before, y1 - before
        outlines[b, 2], outlines[b, 3] = x2 - before + thickness, y2 - before + thickness
        advance, descent = 1.0, 0  # getTextSize: the advances plus the line's thickness
        for i in range(start, ends[b]):
            advance += advances[codes[i] - FIRST]
            descent = max(descent, descents[codes[i] - FIRST])
        start = ends[b]
        label_w, label_h = int(np.rint(advance)) + 3, height + descent + 3
        labels[b, 0], labels[b, 2], labels[b, 3] = x1, label_w, label_h
        labels[b, 1] = y1 - label_h + 1 if y1 - label_h + 1 >= 0 else y1


@njit("void(uint8[:, ::1], int64[:, ::1], int64, uint8[::1])", cache=True, nogil=True)
def _draw_outlines(target: np.ndarray, boxes: np.ndarray, thickness: int,
                   colour: np.ndarray) -> None:  # pragma: no cover - compiled
    """Draws the outlines, box by box and row by row.

    The top and bottom edges are drawn as long runs of pixels, the sides as short ones.
    """
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


@njit("void(uint8[:, ::1], float64[:, ::1], int64, uint8[::1], "
      "Array(uint8, 1, 'C', readonly=True), int64[::1], uint8[:, :, ::1], int64[:, ::1], "
      "float64[::1], int64[::1], int64, int64, int64)", cache=True, nogil=True)
def _draw(rows: np.ndarray, boxes: np.ndarray, thickness: int, colour: np.ndarray,
          codes: np.ndarray, ends: np.ndarray, cells: np.ndarray, ink: np.ndarray,
          advances: np.ndarray, descents: np.ndarray, height: int, pen_x: int,
          pen_y: int) -> None:  # pragma: no cover - compiled
    """Lays out and draws all outlines, then all labels, on ``rows``.

    ``rows`` is the image as ``height x width * 3`` bytes.
    """
    count = boxes.shape[0]
    outlines = np.empty((count, 4), dtype=np.int64)
    labels = np.empty((count, 4), dtype=np.int64)
    _layout(boxes, thickness, codes, ends, advances, descents, height, outlines, labels)
    _draw_outlines(rows, outlines, thickness, colour)
    image_h, image_w = rows.shape[0], rows.shape[1] // 3
    start = 0
    for b in range(count):
        x0, y0 = labels[b, 0], labels[b, 1]
        left, top = max(x0, 0), max(y0, 0)
        right, bottom = min(x0 + labels[b, 2], image_w), min(y0 + labels[b, 3], image_h)
        first, start = start, ends[b]
        if left >= right or top >= bottom:
            continue
        for y in range(top, bottom):
            rows[y, 3 * left:3 * right] = LABEL_GREY
        pen, baseline = x0 + 1.0, y0 + height + 1  # putText's origin in the label
        for i in range(first, ends[b]):
            glyph = codes[i] - FIRST
            # the cell's top-left corner in the image, the character at the nearest pixel
            cell_x, cell_y = int(np.rint(pen)) - pen_x, baseline - pen_y
            pen += advances[glyph]
            for cy in range(max(ink[glyph, 1], top - cell_y), min(ink[glyph, 3], bottom - cell_y)):
                row, cell = rows[cell_y + cy], cells[glyph, cy]
                for cx in range(max(ink[glyph, 0], left - cell_x),
                                min(ink[glyph, 2], right - cell_x)):
                    grey, at = cell[cx], 3 * (cell_x + cx)
                    if grey < row[at]:  # the darker where two characters' edges meet
                        row[at] = grey
                        row[at + 1] = grey
                        row[at + 2] = grey
