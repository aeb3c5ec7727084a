"""Camera sources read from ROS bags (cyborg.vision.bag_source).

ROS 1 bags and ROS 2 bags (sqlite3 and mcap, opened through the folder or the storage file)
with image and depth topics paired by exact stamp, stereo topics, compressed JPEG topics,
topics chosen explicitly or found by name, and clear errors for wrong topics, short messages,
depth maps of another size and missing or corrupt bags. Bags are written with rosbags' own
writers (tests/vision/ros_fixtures.py).
"""

from __future__ import annotations

import shutil
import sqlite3
from pathlib import Path

import numpy as np
import pytest

from cyborg.vision import VisionError
from cyborg.vision.bag_source import BagSource
from cyborg.vision.sources import open_source
from tests.vision.ros_fixtures import (
    COLOUR_TOPIC,
    COMPRESSED,
    DEPTH_TOPIC,
    IMAGE,
    JAZZY,
    NOETIC,
    STAMPS,
    Bag,
    Message,
    camera_bag,
    compressed_message,
    image_message,
)
from tests.vision.source_fixtures import T0, frames_of, same_depth, texture

BAG_KINDS = [("ros1", "rgb8", "32FC1"), ("sqlite3", "bgr8", "16UC1"),
             ("mcap", "rgb8", "32FC1")]


@pytest.mark.parametrize(("kind", "colour", "depth"), BAG_KINDS)
def test_bag_pairs_image_and_depth_by_exact_stamp(tmp_path: Path, kind: str, colour: str,
                                                  depth: str) -> None:
    store = NOETIC if kind == "ros1" else JAZZY
    bag, expected = camera_bag(store, colour, depth)
    path = bag.write(tmp_path / ("cam.bag" if kind == "ros1" else "cam"), kind)
    source = BagSource(path)
    assert source.topics == {"image": COLOUR_TOPIC, "depth": DEPTH_TOPIC}
    assert source.length == 3  # image messages: an upper bound of the frames
    frames = frames_of(source)
    assert [frame.stamp_ns for frame in frames] == [STAMPS[0], STAMPS[3]]
    assert [frame.index for frame in frames] == [0, 1]
    for frame, k in zip(frames, (0, 3), strict=True):
        np.testing.assert_array_equal(frame.left, expected.images[k])
        same_depth(frame.depth, expected.depths[k])
        assert frame.depth is not None and np.isnan(frame.depth[1, 2])  # unknown stays NaN
        assert frame.right is None
        assert frame.frame_id == "camera_left"  # the image's, not the depth map's
    assert source.dropped == 2


def test_ros1_bag_with_an_upper_case_suffix_is_named_as_a_bag_to_rename(tmp_path: Path) -> None:
    bag, _ = camera_bag(NOETIC, "rgb8", "32FC1")
    upper = tmp_path / "CAM.BAG"
    bag.write(tmp_path / "cam.bag", "ros1").rename(upper)
    with pytest.raises(VisionError, match=r"CAM\.BAG: .*rename it to CAM\.bag"):
        open_source(str(upper))


@pytest.mark.parametrize("kind", ["sqlite3", "mcap"])
def test_ros2_storage_file_opens_through_its_bag_folder(tmp_path: Path, kind: str) -> None:
    bag, _ = camera_bag(JAZZY, "bgr8", "32FC1")
    folder = bag.write(tmp_path / "bag", kind)
    [storage] = [path for path in folder.iterdir() if path.suffix in (".db3", ".mcap")]
    direct = frames_of(BagSource(storage))
    whole = frames_of(BagSource(folder))
    assert [frame.stamp_ns for frame in direct] == [frame.stamp_ns for frame in whole] \
        == [STAMPS[0], STAMPS[3]]
    np.testing.assert_array_equal(direct[1].left, whole[1].left)
    loose = tmp_path / "elsewhere" / storage.name
    loose.parent.mkdir()
    shutil.copy(storage, loose)
    with pytest.raises(VisionError, match=r"metadata\.yaml"):
        BagSource(loose)


def test_bag_without_message_definitions_is_read_with_standard_types(tmp_path: Path) -> None:
    """ROS 2 bags before Iron carry no message definitions."""
    bag, expected = camera_bag(JAZZY, "bgr8", "16UC1")
    folder = bag.write(tmp_path / "humble", "sqlite3")
    with sqlite3.connect(folder / "humble.db3") as db:
        db.execute("DELETE FROM message_definitions")
    frames = frames_of(BagSource(folder))
    assert len(frames) == 2
    same_depth(frames[1].depth, expected.depths[3])


def test_explicit_topics_and_clear_errors_for_wrong_ones(tmp_path: Path) -> None:
    bag, _ = camera_bag(JAZZY, "bgr8", "32FC1")
    path = bag.write(tmp_path / "bag", "sqlite3")
    only_images = BagSource(path, image_topic=COLOUR_TOPIC, depth_topic=None)
    assert only_images.topics["image"] == COLOUR_TOPIC
    with pytest.raises(VisionError) as error:
        BagSource(path, image_topic="/camera/left/image_rect")
    assert "'/camera/left/image_rect'" in str(error.value)
    assert f"image topics: {COLOUR_TOPIC}, {DEPTH_TOPIC}" in str(error.value)
    with pytest.raises(VisionError, match="no image topic '/chatter'"):
        BagSource(path, depth_topic="/chatter")


def test_bag_with_stereo_topics_finds_left_right_and_depth(tmp_path: Path) -> None:
    left, right = texture(4, 6, 1), texture(4, 6, 2)
    metres = np.full((4, 6), 1.5, np.float32)
    topics = ("/zed/left/image_rect_color", "/zed/right/image_rect_color",
              "/zed/depth/depth_registered")
    bag = Bag([Message(topics[0], IMAGE, T0, image_message(JAZZY, T0, left, "bgr8")),
               Message(topics[1], IMAGE, T0, image_message(JAZZY, T0, right, "bgr8")),
               Message(topics[2], IMAGE, T0, image_message(JAZZY, T0, metres, "32FC1"))])
    source = BagSource(bag.write(tmp_path / "zed", "mcap"))
    assert source.topics == {"image": topics[0], "right": topics[1], "depth": topics[2]}
    [frame] = frames_of(source)
    assert frame.right is not None
    np.testing.assert_array_equal(frame.right, right)
    same_depth(frame.depth, metres)


def test_bag_with_two_unnamed_image_topics_asks_which(tmp_path: Path) -> None:
    image = texture(2, 2, 0)
    bag = Bag([Message(topic, IMAGE, T0, image_message(JAZZY, T0, image, "bgr8"))
               for topic in ("/front/image_raw", "/rear/image_raw")])
    path = bag.write(tmp_path / "two", "sqlite3")
    with pytest.raises(VisionError, match=r"/front/image_raw, /rear/image_raw.*--image-topic"):
        BagSource(path)
    assert len(frames_of(BagSource(path, image_topic="/rear/image_raw"))) == 1


def test_compressed_jpeg_topic(tmp_path: Path) -> None:
    ramp = np.linspace(0, 255, 32, dtype=np.uint8)
    image = np.dstack([np.tile(ramp, (24, 1)), np.tile(ramp[::-1], (24, 1)),
                       np.full((24, 32), 90, np.uint8)])
    topic = "/camera/image_raw/compressed"
    bag = Bag([Message(topic, COMPRESSED, T0 + k, compressed_message(JAZZY, T0 + k, image))
               for k in range(2)])
    source = BagSource(bag.write(tmp_path / "jpeg", "mcap"))
    assert source.topics == {"image": topic}
    frames = frames_of(source)
    assert [frame.stamp_ns for frame in frames] == [T0, T0 + 1]
    for frame in frames:
        assert frame.left.shape == (24, 32, 3)
        assert np.abs(frame.left.astype(int) - image).mean() < 3  # jpeg is lossy, not wrong


def test_compressed_topic_is_not_taken_for_depth(tmp_path: Path) -> None:
    image = texture(8, 8, 0)
    bag = Bag([Message("/camera/color/image_raw", IMAGE, T0,
                       image_message(JAZZY, T0, image, "bgr8")),
               Message("/camera/depth/image_raw/compressedDepth", COMPRESSED, T0,
                       compressed_message(JAZZY, T0, image))])
    path = bag.write(tmp_path / "bag", "sqlite3")
    assert BagSource(path).topics == {"image": "/camera/color/image_raw"}
    with pytest.raises(VisionError, match="must be a sensor_msgs/msg/Image"):
        BagSource(path, depth_topic="/camera/depth/image_raw/compressedDepth")


def test_bag_message_with_too_little_data_names_the_topic(tmp_path: Path) -> None:
    message = image_message(JAZZY, T0, texture(4, 4, 0), "bgr8")
    message.data = message.data[:40]  # 48 bytes are needed
    path = Bag([Message(COLOUR_TOPIC, IMAGE, T0, message)]).write(tmp_path / "short", "mcap")
    with pytest.raises(VisionError, match=rf"{COLOUR_TOPIC}: .*needs 48 bytes.* 40"):
        frames_of(BagSource(path))


def test_bag_depth_of_another_size_is_refused(tmp_path: Path) -> None:
    bag = Bag([Message(COLOUR_TOPIC, IMAGE, T0, image_message(JAZZY, T0, texture(4, 4, 0),
                                                             "bgr8")),
               Message(DEPTH_TOPIC, IMAGE, T0, image_message(JAZZY, T0,
                                                             np.ones((2, 2), np.float32),
                                                             "32FC1"))])
    path = bag.write(tmp_path / "sizes", "sqlite3")
    with pytest.raises(VisionError, match=r"sizes at stamp .*depth map is 2x2.*4x4"):
        frames_of(BagSource(path))


def test_missing_and_corrupt_bags(tmp_path: Path) -> None:
    with pytest.raises(VisionError, match=r"gone\.bag: not found"):
        BagSource(tmp_path / "gone.bag")
    corrupt = tmp_path / "corrupt.bag"
    corrupt.write_bytes(np.random.default_rng(0).bytes(300))
    with pytest.raises(VisionError, match=r"corrupt\.bag: cannot be read"):
        BagSource(corrupt)
