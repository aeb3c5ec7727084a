"""Opening a camera source from its description (cyborg.vision.sources.open_source).

An image (with a depth map), a stereo pair of images, a folder, a video or a pair of videos,
a ROS 1 or ROS 2 bag, a camera by number; and errors that say what is missing or not
understood.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from cyborg.vision import VisionError
from cyborg.vision.bag_source import BagSource
from cyborg.vision.file_sources import FolderSource, ImageSource, VideoSource
from cyborg.vision.sources import SourceOptions, camera_index, open_source
from tests.vision.ros_fixtures import JAZZY, NOETIC, camera_bag
from tests.vision.source_fixtures import (
    frames_of,
    grey_levels,
    same_depth,
    texture,
    write_image,
    write_npy,
    write_video,
)


def test_open_source_dispatches_on_the_description(tmp_path: Path) -> None:
    left = write_image(tmp_path / "left.png", texture(4, 6, 1))
    right = write_image(tmp_path / "right.png", texture(4, 6, 2))
    depth = write_npy(tmp_path / "depth.npy", np.ones((4, 6), np.float32))
    image = open_source(str(left), SourceOptions(depth=depth))
    assert isinstance(image, ImageSource)
    [frame] = frames_of(image)
    same_depth(frame.depth, np.ones((4, 6)))

    stereo = open_source(f"{left}, {right}")
    assert isinstance(stereo, ImageSource)
    [pair] = frames_of(stereo)
    assert pair.right is not None
    np.testing.assert_array_equal(pair.right, texture(4, 6, 2))

    assert isinstance(open_source(str(tmp_path)), FolderSource)
    video = write_video(tmp_path / "v.avi", grey_levels([9, 9]))
    assert isinstance(open_source(str(video)), VideoSource)
    videos = open_source(f"{video},{video}")
    assert isinstance(videos, VideoSource) and videos.right_capture is not None
    videos.close()

    bag, _ = camera_bag(NOETIC, "bgr8", "32FC1")
    ros1 = bag.write(tmp_path / "cam.bag", "ros1")
    ros2 = camera_bag(JAZZY, "bgr8", "32FC1")[0].write(tmp_path / "cam2", "mcap")
    for path in (ros1, ros2):
        source = open_source(str(path))
        assert isinstance(source, BagSource) and len(frames_of(source)) == 2


def test_camera_descriptions() -> None:
    assert camera_index("camera:0") == 0
    assert camera_index("camera:12") == 12
    assert camera_index("3") == 3
    for text in ("camera:", "camera:x", "camera:-1", "cam3", "camera:²", "²", "left.png"):
        assert camera_index(text) is None, text
    with pytest.raises(VisionError, match="camera 99: cannot be opened"):
        open_source("camera:99")
    with pytest.raises(VisionError, match="camera:front: a camera is 'camera:N'"):
        open_source("camera:front")


def test_open_source_errors(tmp_path: Path) -> None:
    with pytest.raises(VisionError, match=r"source .*nothing\.png: not found"):
        open_source(str(tmp_path / "nothing.png"))
    notes = tmp_path / "notes.txt"
    notes.write_text("hello")
    with pytest.raises(VisionError, match=r"unknown kind of file '\.txt'"):
        open_source(str(notes))
    with pytest.raises(VisionError, match="bus sources need a bus node"):
        open_source("bus:/camera/image_raw")
    pair = open_source(f"{write_image(tmp_path / 'l.png', texture(2, 2, 0))},"
                       f"{tmp_path / 'missing.png'}")
    with pytest.raises(VisionError, match=r"image .*missing\.png: not found"):
        next(iter(pair))
