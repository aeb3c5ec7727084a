"""Camera sources on files and devices: images, image folders, videos, stereo pairs, cameras.

===========================  =================================================================
source                       frames
===========================  =================================================================
:class:`ImageSource`         one image (with a right image and/or a depth map file)
:class:`FolderSource`        a folder of images in name order; ``left/`` + ``right/`` and/or
                             ``depth/`` subfolders pair files by name (``0001.png`` with
                             ``depth/0001.npy``); unpaired files are counted and dropped
:class:`VideoSource`         a video file or a local camera (OpenCV capture); two videos for
                             a stereo pair; ``side_by_side`` splits each frame into left and
                             right halves, as a ZED camera delivers them
===========================  =================================================================

Stamps: a file named by an integer of 16 or more digits is taken as nanoseconds (how
recorders name frames); otherwise frames are stamped ``index / rate``. Videos use the
container's timestamps and cameras the time of capture.
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from pathlib import Path

import cv2
import numpy as np
from typing_extensions import override

from cyborg.vision.frames import Frame, FrameSource, VisionError
from cyborg.vision.image_files import (
    DEPTH_SUFFIXES,
    IMAGE_SUFFIXES,
    as_bgr,
    read_depth,
    read_image,
)

DEFAULT_RATE = 30.0


def stamp_for(path: Path, index: int, rate: float) -> int:
    """The stamp (ns) of the file ``path``, the ``index``-th at ``rate`` frames per second.

    A name that is an integer of 16 or more digits is the stamp; otherwise ``index / rate`` s.
    """
    stem = path.stem
    if stem.isascii() and stem.isdigit() and len(stem) >= 16:
        return int(stem)
    return round(index * 1e9 / rate)


def split_side_by_side(image: np.ndarray, what: str) -> tuple[np.ndarray, np.ndarray]:
    """Left and right halves of a side-by-side stereo frame (a ZED frame)."""
    width = image.shape[1]
    if width % 2:
        raise VisionError(f"{what}: a side-by-side frame must have an even width, not {width}")
    half = width // 2
    return np.ascontiguousarray(image[:, :half]), np.ascontiguousarray(image[:, half:])


class ImageSource(FrameSource):
    """A single image, optionally with its right image and depth map."""

    def __init__(self, path: Path, *, right: Path | None = None, depth: Path | None = None,
                 side_by_side: bool = False) -> None:
        super().__init__()
        self.name, self.length = str(path), 1
        self.path, self.right, self.depth, self.side_by_side = path, right, depth, side_by_side
        read_image(path)  # fail now, not in the middle of a run

    @override
    def frames(self) -> Iterator[Frame]:
        left = read_image(self.path)
        right = read_image(self.right) if self.right is not None else None
        if self.side_by_side:
            left, right = split_side_by_side(left, str(self.path))
        depth = read_depth(self.depth) if self.depth is not None else None
        yield _frame(stamp_for(self.path, 0, DEFAULT_RATE), left, right, depth, 0, self.path)


def _frame(stamp: int, left: np.ndarray, right: np.ndarray | None, depth: np.ndarray | None,
           index: int, where: Path | str) -> Frame:
    try:
        return Frame(stamp, left, right, depth, index=index)
    except VisionError as exc:
        raise VisionError(f"{where}: {exc}") from None


def _files(folder: Path, suffixes: frozenset[str]) -> dict[str, Path]:
    """The folder's files with one of ``suffixes``, by name without suffix.

    The name pairs a left image with its right image and depth map; two files of one name are
    an error.
    """
    found: dict[str, Path] = {}
    for path in sorted(folder.iterdir()):
        if not (path.is_file() and path.suffix.lower() in suffixes):
            continue
        if path.stem in found:
            raise VisionError(f"image folder {folder}: {found[path.stem].name} and {path.name} "
                              "have the same name; frames are paired by name, keep one")
        found[path.stem] = path
    return found


class FolderSource(FrameSource):
    """Images of a folder in name order, with right images and depth maps paired by name."""

    def __init__(self, folder: Path, *, rate: float = DEFAULT_RATE,
                 side_by_side: bool = False) -> None:
        super().__init__()
        if not folder.is_dir():
            raise VisionError(f"image folder {folder}: not found")
        if not rate > 0:
            raise VisionError(f"image folder {folder}: the frame rate must be positive, not {rate}")
        self.name, self.rate, self.side_by_side = str(folder), rate, side_by_side
        left_dir = folder / "left" if (folder / "left").is_dir() else folder
        self.left = _files(left_dir, IMAGE_SUFFIXES)
        if not self.left:
            raise VisionError(f"image folder {left_dir}: no images "
                              f"({', '.join(sorted(IMAGE_SUFFIXES))})")
        self.right = _files(folder / "right", IMAGE_SUFFIXES) if (folder / "right").is_dir() \
            else None
        self.depth = _files(folder / "depth", DEPTH_SUFFIXES) if (folder / "depth").is_dir() \
            else None
        wanted = [name for name in self.left
                  if (self.right is None or name in self.right)
                  and (self.depth is None or name in self.depth)]
        # every file left without its partner is dropped, and counted: an image without its
        # depth map, and also its right image (as a bag's pairer counts every unpaired message)
        used = set(wanted)
        self.dropped = sum(len(set(files) - used)
                           for files in (self.left, self.right, self.depth) if files is not None)
        self.names = wanted
        self.length = len(wanted)

    @override
    def frames(self) -> Iterator[Frame]:
        for index, name in enumerate(self.names):
            path = self.left[name]
            left = read_image(path)
            right = read_image(self.right[name]) if self.right is not None else None
            if self.side_by_side:
                left, right = split_side_by_side(left, str(path))
            depth = read_depth(self.depth[name]) if self.depth is not None else None
            yield _frame(stamp_for(path, index, self.rate), left, right, depth, index, path)


class VideoSource(FrameSource):
    """Frames of a video file or a local camera; a second video gives the right images."""

    def __init__(self, video: Path | int, *, right: Path | None = None,
                 side_by_side: bool = False, width: int = 0, height: int = 0) -> None:
        super().__init__()
        self.camera = isinstance(video, int)
        self.name = f"camera {video}" if self.camera else str(video)
        self.side_by_side = side_by_side
        self.capture = self._open(video)
        if width and height:
            self.capture.set(cv2.CAP_PROP_FRAME_WIDTH, width)
            self.capture.set(cv2.CAP_PROP_FRAME_HEIGHT, height)
        try:
            self.right_capture = self._open(right) if right is not None else None
        except VisionError:
            self.capture.release()
            raise
        counts = [int(capture.get(cv2.CAP_PROP_FRAME_COUNT))
                  for capture in (self.capture, self.right_capture) if capture is not None]
        # a stereo pair ends with its shorter video
        self.length = min(counts) if min(counts) > 0 and not self.camera else None

    def _open(self, video: Path | int) -> cv2.VideoCapture:
        if isinstance(video, Path) and not video.is_file():
            raise VisionError(f"video {video}: not found")
        capture = cv2.VideoCapture(video if isinstance(video, int) else str(video))
        if not capture.isOpened():
            what = f"camera {video}" if isinstance(video, int) else f"video {video}"
            raise VisionError(f"{what}: cannot be opened (no such device, or a format "
                              "OpenCV cannot read)")
        return capture

    def frames(self) -> Iterator[Frame]:
        """The frames from the start (a video file is rewound; a camera goes on live)."""
        if not self.camera:
            for capture in (self.capture, self.right_capture):
                if capture is not None:
                    capture.set(cv2.CAP_PROP_POS_FRAMES, 0)
        index = 0
        while True:
            ok, image = self.capture.read()
            if not ok or image is None:
                return
            stamp = time.time_ns() if self.camera else \
                round(self.capture.get(cv2.CAP_PROP_POS_MSEC) * 1e6)
            left, right = as_bgr(image, self.name), None
            if self.right_capture is not None:
                ok, other = self.right_capture.read()
                if not ok or other is None:
                    return
                right = as_bgr(other, f"{self.name} (right)")
            elif self.side_by_side:
                left, right = split_side_by_side(left, self.name)
            yield _frame(stamp, left, right, None, index, f"{self.name} frame {index}")
            index += 1

    @override
    def close(self) -> None:
        self.capture.release()
        if self.right_capture is not None:
            self.right_capture.release()
