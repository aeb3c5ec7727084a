"""A camera frame (cyborg.vision.frames.Frame) checks what it is given.

A left image must be BGR uint8, a stereo pair must have one size, and a depth map must be
float32 metres of the image's size.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from cyborg.vision import Frame, VisionError
from cyborg.vision.file_sources import ImageSource
from tests.vision.source_fixtures import frames_of, texture, write_image, write_npy


def test_depth_map_of_another_size_is_refused(tmp_path: Path) -> None:
    image = write_image(tmp_path / "image.png", texture(4, 6, 0))
    depth = write_npy(tmp_path / "depth.npy", np.ones((6, 4), np.float32))
    with pytest.raises(VisionError, match=r"image\.png: depth map is 4x6 but the image is 6x4"):
        frames_of(ImageSource(image, depth=depth))


def test_frame_checks_what_it_is_given() -> None:
    with pytest.raises(VisionError, match="left image must be a BGR uint8"):
        Frame(0, np.zeros((2, 2), np.uint8))
    with pytest.raises(VisionError, match="stereo pair must have one size"):
        Frame(0, texture(2, 2, 0), right=texture(2, 3, 0))
    with pytest.raises(VisionError, match="float32 array in metres"):
        Frame(0, texture(2, 2, 0), depth=np.ones((2, 2)))
