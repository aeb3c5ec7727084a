"""The labels' font: OpenCV's text, each character rendered once, for a compiled loop to place.

``cv2.putText`` per label is a Python call with its own argument conversion and text layout,
and the annotated image is drawn right after the network has run, when none of that is in the
CPU's caches: five captions cost about 0.3 ms that way (with ``getTextSize`` to size their
labels). A caption is its characters side by side, each moved on from the last by the font's
advance. :class:`GlyphFont` renders each printable ASCII character once per scale,
anti-aliased, grey on white, in a cell of its own; the annotated image's compiled loop
(:mod:`cyborg.vision.annotate`) then composes captions from these cells, keeping the darker
pixel where two characters' edges meet. Each character is pixel for pixel what ``putText``
draws of it. OpenCV 5.0's font advances by whole pixels, and its characters' edges do not meet:
the composed caption is pixel for pixel what ``putText`` draws of the whole text. OpenCV 4's
Hershey font advances by fractions of a pixel, which ``putText`` keeps and the composition
rounds: characters may then sit up to half a pixel from where ``putText`` puts them. OpenCV 5.1
kerns some pairs of characters (``rc``, ``Te``) a pixel or a few closer or further apart; the
composition does not, so such a caption is that much wider or narrower than ``putText``'s.

    font = GlyphFont.at(1.08)             # cells, ink boxes, advances, descents
    codes, ends = encode(["person: 0.93 (2.37 m)", "car: 0.71 (? m)"])   # for the loop

Sizes follow ``cv2.getTextSize`` (thickness 1): a text is as wide as its characters' advances
plus one pixel, rises ``height`` pixels above the baseline, and reaches below it as far as its
deepest character (``descents``). Characters outside printable ASCII are drawn as ``?``.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from dataclasses import dataclass
from itertools import accumulate

import cv2
import numpy as np

FONT = cv2.FONT_HERSHEY_SIMPLEX
FIRST, LAST = 32, 126
"""The printable ASCII characters: space to tilde."""
UNKNOWN = ord("?")
BACKGROUND, INK = 255, 0
"""Grey levels of a cell: white paper, black text."""
_MARGIN = 4
"""Pixels around the pen's box in a cell, for anti-aliased edges that spill past it."""
_REPEAT = 101
"""A character's advance is measured over this many copies of it: to 1/100 of a pixel."""


@dataclass(frozen=True)
class GlyphFont:
    """OpenCV's ``FONT_HERSHEY_SIMPLEX`` at one scale, as one grey cell per character.

    A character drawn with its pen at ``(x, y)`` (the left end of its baseline) puts cell pixel
    ``(column, row)`` at ``(x + column - pen_x, y + row - pen_y)``.
    """

    scale: float
    cells: np.ndarray
    """``characters x rows x columns`` uint8 grey levels (:data:`BACKGROUND` around the ink)."""
    ink: np.ndarray
    """``characters x 4`` int64: left, top, right, bottom (exclusive) of the ink in its cell,
    all zero for a blank character."""
    advances: np.ndarray
    """float64 per character: how far the pen moves after it, in pixels."""
    descents: np.ndarray
    """int64 per character: how far it reaches below the baseline."""
    height: int
    """How far text rises above the baseline."""
    pen_x: int
    pen_y: int

    @staticmethod
    @functools.lru_cache(maxsize=8)
    def at(scale: float) -> GlyphFont:
        """The font at ``scale`` (``putText``'s ``fontScale``), rendered on first use."""
        if not scale > 0:
            raise ValueError(f"font scale must be positive, not {scale}")
        characters = [chr(code) for code in range(FIRST, LAST + 1)]
        singles = [cv2.getTextSize(text, FONT, scale, 1) for text in characters]
        height = singles[0][0][1]
        advances = [(cv2.getTextSize(text * _REPEAT, FONT, scale, 1)[0][0] - width)
                    / (_REPEAT - 1)
                    for text, ((width, _h), _d) in zip(characters, singles, strict=True)]
        descents = [descent for (_size, descent) in singles]
        pen_x, pen_y = _MARGIN, _MARGIN + height
        cells = np.full((len(characters), pen_y + max(descents) + _MARGIN,
                         math.ceil(max(advances)) + 2 * _MARGIN), BACKGROUND, dtype=np.uint8)
        ink = np.zeros((len(characters), 4), dtype=np.int64)
        for index, text in enumerate(characters):
            cv2.putText(cells[index], text, (pen_x, pen_y), FONT, scale, INK, 1, cv2.LINE_AA)
            rows, columns = np.nonzero(cells[index] != BACKGROUND)
            if len(rows):
                ink[index] = (columns.min(), rows.min(), columns.max() + 1, rows.max() + 1)
        return GlyphFont(scale, cells, ink, np.array(advances, dtype=np.float64),
                         np.array(descents, dtype=np.int64), height, pen_x, pen_y)


def encode(texts: Sequence[str]) -> tuple[np.ndarray, np.ndarray]:
    """The texts' character codes one after another (uint8), and where each text ends (int64).

    Anything outside printable ASCII becomes ``?``.
    """
    joined = "".join(texts).encode("ascii", "replace").translate(_PRINTABLE)
    return (np.frombuffer(joined, dtype=np.uint8),
            np.fromiter(accumulate(map(len, texts)), dtype=np.int64, count=len(texts)))


_PRINTABLE = bytes(code if FIRST <= code <= LAST else UNKNOWN for code in range(256))
"""A byte translation table: printable ASCII stays, anything else becomes ``?``."""
