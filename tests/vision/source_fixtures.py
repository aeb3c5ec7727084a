"""Helpers for the tests of camera sources (tests/vision/test_*source*.py and their kin).

Every input is generated small in ``tmp_path``: images and depth maps with OpenCV and numpy,
videos with ``cv2.VideoWriter``. Also: reading every frame of a source, and comparing depth
maps. ROS messages and bags are built by tests/vision/ros_fixtures.py.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import cv2
import numpy as np

from cyborg.vision import Frame

T0 = 1_700_000_000_123_456_789
"""A stamp with nanoseconds that a float would round away."""


def texture(height: int, width: int, seed: int) -> np.ndarray:
    return np.random.default_rng(seed).integers(0, 256, (height, width, 3), dtype=np.uint8)


def write_image(path: Path, image: np.ndarray) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    assert cv2.imwrite(str(path), image), path
    return path


def write_npy(path: Path, array: np.ndarray) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    np.save(path, array)
    return path


def frames_of(source: Any) -> list[Frame]:
    with source:
        return list(source)


def same_depth(actual: np.ndarray | None, expected: np.ndarray) -> None:
    assert actual is not None
    assert actual.dtype == np.float32
    np.testing.assert_allclose(actual, expected, rtol=1e-6, equal_nan=True)


def write_video(path: Path, frames: list[np.ndarray], fps: float = 10.0) -> Path:
    fourcc = {".avi": "MJPG", ".mp4": "mp4v"}[path.suffix]
    height, width = frames[0].shape[:2]
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter.fourcc(*fourcc), fps, (width, height))
    assert writer.isOpened(), f"this OpenCV cannot write {fourcc} {path.suffix}"
    for frame in frames:
        writer.write(frame)
    writer.release()
    return path


def grey_levels(levels: list[int], height: int = 32, width: int = 48) -> list[np.ndarray]:
    return [np.full((height, width, 3), level, np.uint8) for level in levels]


def mean_levels(images: list[np.ndarray]) -> list[int]:
    return [round(float(image.mean())) for image in images]
