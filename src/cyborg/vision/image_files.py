"""Reading images and depth maps from files, with errors that name the file.

Images: anything OpenCV reads (PNG, JPEG, TIFF, BMP, ...); grey and alpha images become BGR,
16-bit ones are scaled to 8 bits. Depth maps: ``.npy``/``.npz`` arrays (``float32`` metres or
``uint16`` millimetres) and 16-bit PNG/TIFF in millimetres; see :mod:`cyborg.vision.depth`.
"""

from __future__ import annotations

import zipfile
from pathlib import Path

import cv2
import numpy as np

from cyborg.vision.depth import depth_in_metres
from cyborg.vision.frames import VisionError

IMAGE_SUFFIXES = frozenset({".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff", ".webp", ".ppm",
                            ".pgm"})
VIDEO_SUFFIXES = frozenset({".mp4", ".avi", ".mkv", ".mov", ".webm", ".m4v", ".mpg", ".mpeg"})
DEPTH_SUFFIXES = frozenset({".npy", ".npz", ".png", ".tif", ".tiff"})


def as_bgr(image: np.ndarray, what: str) -> np.ndarray:
    """Any grey, BGR or BGRA image of 8 or 16 bits as BGR ``uint8``."""
    if image.dtype == np.uint16:
        image = (image >> 8).astype(np.uint8)
    elif image.dtype != np.uint8:
        raise VisionError(f"{what}: {image.dtype} pixels; expected 8- or 16-bit images")
    if image.ndim == 2:
        return cv2.cvtColor(image, cv2.COLOR_GRAY2BGR)
    if image.ndim == 3 and image.shape[2] == 4:
        return cv2.cvtColor(image, cv2.COLOR_BGRA2BGR)
    if image.ndim == 3 and image.shape[2] == 3:
        return image
    raise VisionError(f"{what}: image of shape {image.shape} is not grey, BGR or BGRA")


def read_image(path: Path) -> np.ndarray:
    """A BGR ``uint8`` image from a file, or a :class:`VisionError` naming it."""
    if not path.is_file():
        raise VisionError(f"image {path}: {'is a folder' if path.is_dir() else 'not found'}")
    image = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
    if image is None or image.size == 0:
        raise VisionError(f"image {path}: cannot be decoded (corrupt, truncated or not an "
                          "image)")
    return as_bgr(image, f"image {path}")


def read_depth(path: Path) -> np.ndarray:
    """A depth map in ``float32`` metres (NaN where unknown) from a file."""
    if not path.is_file():
        raise VisionError(f"depth map {path}: {'is a folder' if path.is_dir() else 'not found'}")
    array: np.ndarray | None
    if path.suffix.lower() in (".npy", ".npz"):
        try:
            loaded = np.load(path, allow_pickle=False)
            if isinstance(loaded, np.lib.npyio.NpzFile):
                with loaded:  # an archive keeps its file open until closed
                    array = loaded[loaded.files[0]]
            else:
                array = loaded
        except (ValueError, OSError, EOFError, zipfile.BadZipFile, IndexError) as exc:
            raise VisionError(f"depth map {path}: not a readable numpy array ({exc})") from exc
    else:
        array = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
        if array is None:
            raise VisionError(f"depth map {path}: cannot be decoded")
        if array.dtype != np.uint16 and array.dtype != np.float32:
            raise VisionError(f"depth map {path}: {array.dtype} pixels; a depth image must be "
                              "16-bit millimetres or 32-bit float metres")
    return depth_in_metres(np.asarray(array), f"depth map {path}")
