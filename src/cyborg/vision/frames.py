"""A camera frame, and the interface every camera source shares.

A :class:`Frame` is what one exposure of the camera gives: the left image (BGR, ``uint8``,
height x width x 3) with its timestamp, and, when the source has them, the right image of a
stereo pair and a depth map in metres (``float32``, NaN where unknown) registered to the left
image. Sources (:mod:`cyborg.vision.sources`, :mod:`cyborg.vision.bag_source`,
:mod:`cyborg.vision.bus_source`) are iterables of frames, with a :attr:`~FrameSource.length`
when they know it::

    with open_source("ride.mp4") as source:
        for frame in source:
            ...
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np


class VisionError(ValueError):
    """Input the vision pipeline cannot use: the message names the file, topic or field."""


@dataclass(frozen=True)
class Frame:
    """One timestamped camera frame.

    ``stamp_ns`` is the capture time in nanoseconds (a bag's or message's stamp, else the time
    the frame was read); ``index`` counts frames from 0 in the order the source gave them.
    """

    stamp_ns: int
    left: np.ndarray
    right: np.ndarray | None = None
    depth: np.ndarray | None = None
    frame_id: str = "camera"
    index: int = 0

    def __post_init__(self) -> None:
        check_image(self.left, "left image")
        if self.right is not None:
            check_image(self.right, "right image")
            if self.right.shape != self.left.shape:
                raise VisionError(f"right image is {_size(self.right)}, the left image "
                                  f"{_size(self.left)}: a stereo pair must have one size")
        if self.depth is not None:
            if self.depth.ndim != 2 or self.depth.dtype != np.float32:
                raise VisionError(f"depth map must be a 2-D float32 array in metres, not "
                                  f"{self.depth.dtype} {self.depth.shape}")
            if self.depth.shape != self.left.shape[:2]:
                raise VisionError(f"depth map is {_size(self.depth)} but the image is "
                                  f"{_size(self.left)}: depth must be registered to the "
                                  "left image, pixel for pixel")

    @property
    def size(self) -> tuple[int, int]:
        """(width, height) of the left image."""
        return int(self.left.shape[1]), int(self.left.shape[0])


def check_image(image: np.ndarray, what: str) -> None:
    """A BGR image: ``uint8``, height x width x 3, not empty."""
    if not isinstance(image, np.ndarray) or image.dtype != np.uint8 or image.ndim != 3 \
            or image.shape[2] != 3 or image.size == 0:
        shape = getattr(image, "shape", None)
        dtype = getattr(image, "dtype", type(image).__name__)
        raise VisionError(f"{what} must be a BGR uint8 array of height x width x 3, not "
                          f"{dtype} {shape}")


def _size(array: np.ndarray) -> str:
    return f"{array.shape[1]}x{array.shape[0]}"


class FrameSource:
    """Base of camera sources: iterate for frames; ``close()`` (or ``with``) releases them.

    :attr:`length` is the number of frames when known (files, bags; an upper bound where
    pairing may drop some), else None. :attr:`dropped` counts what the source had to drop (an
    image without its depth map, or a depth map without its image).
    """

    name = "source"
    length: int | None = None

    def __init__(self) -> None:
        self.dropped = 0

    def frames(self) -> Iterator[Frame]:
        """The frames, in order; raises :class:`VisionError` on data it cannot read."""
        raise NotImplementedError

    def __iter__(self) -> Iterator[Frame]:
        return self.frames()

    def close(self) -> None:
        """Release files and devices; safe to call twice."""

    def __enter__(self) -> FrameSource:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
