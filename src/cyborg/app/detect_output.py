"""Where ``cyborg detect`` puts annotated frames: a video, an image, a folder or a window."""

from __future__ import annotations

import contextlib
from pathlib import Path

import cv2
import numpy as np

from cyborg.app.errors import CommandError
from cyborg.vision.file_sources import DEFAULT_RATE
from cyborg.vision.image_files import IMAGE_SUFFIXES, VIDEO_SUFFIXES
from cyborg.vision.pipeline import Result

_FOURCC = {".mp4": "mp4v", ".m4v": "mp4v", ".mov": "mp4v", ".avi": "MJPG", ".mkv": "MJPG"}


class FrameWriter:
    """Writes each result's annotated image to ``path`` (or shows it with ``show``)."""

    def __init__(self, path: Path | None, *, show: bool = False,
                 rate: float = DEFAULT_RATE) -> None:
        self.path, self.show, self.rate = path, show, rate
        self.wanted = path is not None or show
        self._video: cv2.VideoWriter | None = None
        self.written = 0
        if path is None:
            return
        suffix = path.suffix.lower()
        if suffix and suffix not in IMAGE_SUFFIXES and suffix not in _FOURCC:
            raise CommandError(f"--out {path}: write a video ({', '.join(sorted(_FOURCC))}), "
                               f"an image ({', '.join(sorted(IMAGE_SUFFIXES))}) or a folder")
        if suffix in VIDEO_SUFFIXES and not path.parent.is_dir():
            raise CommandError(f"--out {path}: folder {path.parent} does not exist")

    def write(self, result: Result) -> None:
        """Writes (or shows) the result's annotated image, if it has one."""
        image = result.annotated
        if image is None:
            return
        if self.show:
            self._show(image)
        if self.path is None:
            return
        suffix = self.path.suffix.lower()
        if suffix in _FOURCC:
            self._write_video(image)
        elif suffix in IMAGE_SUFFIXES and self.written == 0:
            self._imwrite(self.path, image)
        else:
            folder = self.path if not suffix else self.path.with_suffix("")
            folder.mkdir(parents=True, exist_ok=True)
            self._imwrite(folder / f"{result.frame.index:06d}.png", image)
        self.written += 1

    def _write_video(self, image: np.ndarray) -> None:
        assert self.path is not None
        if self._video is None:
            height, width = image.shape[:2]
            fourcc = cv2.VideoWriter.fourcc(*_FOURCC[self.path.suffix.lower()])
            self._video = cv2.VideoWriter(str(self.path), fourcc, self.rate, (width, height))
            if not self._video.isOpened():
                raise CommandError(f"--out {self.path}: OpenCV cannot write this video format")
        self._video.write(image)

    @staticmethod
    def _imwrite(path: Path, image: np.ndarray) -> None:
        if not cv2.imwrite(str(path), image):
            raise CommandError(f"--out {path}: cannot write the image")

    def _show(self, image: np.ndarray) -> None:
        try:
            cv2.imshow("cyborg detect", image)
            cv2.waitKey(1)
        except cv2.error as exc:
            raise CommandError("--show needs a display and OpenCV with its GUI (pip install "
                               "opencv-python instead of opencv-python-headless); use --out "
                               "to write the frames instead") from exc

    def close(self) -> None:
        """Finishes the video and closes the window, if any."""
        if self._video is not None:
            self._video.release()
        if self.show:
            with contextlib.suppress(cv2.error):
                cv2.destroyAllWindows()
