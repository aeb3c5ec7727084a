"""Fitting a camera image into the network's input without distorting it (letterboxing).

The image is scaled by one factor so that it fits, and the rest is padded with grey (114).
YOLOX was trained with the image in the top-left corner; the Ultralytics families centre it.
:class:`Letterbox` remembers the scale and offset so boxes go back to image pixels.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np
from numba import njit

PAD_VALUE = 114


@dataclass(frozen=True)
class InputFormat:
    """How a family wants its input: channel order, scaling and where the padding goes."""

    rgb: bool = False
    """True: RGB channel order (Ultralytics, Darknet); False: BGR as captured (YOLOX)."""
    scale: float = 1.0
    """Pixel values are multiplied by this (1/255 for 0..1 inputs; YOLOX wants 0..255)."""
    centred: bool = False
    """True: pad equally on both sides; False: image in the top-left corner."""


@dataclass(frozen=True)
class Letterbox:
    """The scale and offset that map network-input pixels back to image pixels."""

    scale: float
    offset_x: int
    offset_y: int
    image_width: int
    image_height: int


@njit("void(Array(float32, 2, 'A', readonly=True), int64[:], float64, float64, float64, "
      "float64, float64, float64[:, :])", cache=True, nogil=True)
def to_image(boxes: np.ndarray, chosen: np.ndarray, scale: float, offset_x: float,
             offset_y: float, width: float, height: float,
             into: np.ndarray) -> None:  # pragma: no cover - compiled
    """Maps the ``x1, y1, x2, y2`` boxes ``chosen`` from network-input pixels to image pixels.

    The boxes are clipped to the image and written into the first four columns of ``into``'s
    rows. For compiled callers, with a :class:`Letterbox`'s scale and offsets and its image's
    size.
    """
    for row in range(len(chosen)):
        for column in range(4):
            offset, limit = (offset_x, width) if column % 2 == 0 else (offset_y, height)
            into[row, column] = min(max((boxes[chosen[row], column] - offset) / scale, 0.0),
                                    limit)


class Preprocessor:
    """Letterboxes BGR images into a reusable ``1 x 3 x H x W`` float32 input tensor."""

    def __init__(self, input_hw: tuple[int, int], input_format: InputFormat) -> None:
        self.input_hw = input_hw
        self.format = input_format
        self._resized = np.empty((0, 0, 3), dtype=np.uint8)
        self._planes: list[np.ndarray] = []
        self._tensor = np.empty((1, 3, input_hw[0], input_hw[1]), dtype=np.float32)
        self._last: tuple[int, int, int, int] | None = None

    def __call__(self, image: np.ndarray) -> tuple[np.ndarray, Letterbox]:
        """The input tensor (reused by the next call: run the network before calling again)."""
        height, width = image.shape[:2]
        net_h, net_w = self.input_hw
        scale = min(net_w / width, net_h / height)
        new_w, new_h = max(1, round(width * scale)), max(1, round(height * scale))
        offset_x = (net_w - new_w) // 2 if self.format.centred else 0
        offset_y = (net_h - new_h) // 2 if self.format.centred else 0
        placement = (new_w, new_h, offset_x, offset_y)
        if placement != self._last:  # a new size: repaint the padding once
            self._tensor[:] = np.float32(PAD_VALUE * self.format.scale)
            self._resized = np.empty((new_h, new_w, 3), dtype=np.uint8)
            self._planes = [np.empty((new_h, new_w), dtype=np.uint8) for _ in range(3)]
            self._last = placement
        cv2.resize(image, (new_w, new_h), dst=self._resized, interpolation=cv2.INTER_LINEAR)
        # HWC → CHW: OpenCV splits the channels into contiguous planes, which numpy then widens
        # to float (three times faster than numpy converting the strided channels directly)
        cv2.split(self._resized, self._planes)
        planes = self._planes[::-1] if self.format.rgb else self._planes
        target = self._tensor[0, :, offset_y:offset_y + new_h, offset_x:offset_x + new_w]
        for channel, plane in enumerate(planes):
            if self.format.scale == 1.0:
                np.copyto(target[channel], plane)
            else:
                np.multiply(plane, np.float32(self.format.scale), out=target[channel])
        return self._tensor, Letterbox(scale, offset_x, offset_y, width, height)
