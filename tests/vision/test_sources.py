"""Camera sources: image files, folders, videos, ROS bags, messages, pairing and depth.

Every input is generated small in ``tmp_path``: images and depth maps with OpenCV and numpy,
videos with ``cv2.VideoWriter``, bags with rosbags' own writers (ROS 1, ROS 2 sqlite3 and mcap).
"""

from __future__ import annotations

import shutil
import sqlite3
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from rosbags.rosbag1 import Writer as Writer1
from rosbags.rosbag2 import StoragePlugin
from rosbags.rosbag2 import Writer as Writer2
from rosbags.typesys import Stores, get_typestore
from rosbags.typesys.store import Typestore

from cyborg.bus.message_types import MessageTypes
from cyborg.vision import Frame, StereoCalibration, StereoDepth, VisionError, depth_in_metres
from cyborg.vision.bag_source import BagSource
from cyborg.vision.file_sources import FolderSource, ImageSource, VideoSource
from cyborg.vision.image_messages import (
    bgr_to_image,
    compressed_to_bgr,
    depth_to_image,
    image_to_bgr,
    image_to_depth,
)
from cyborg.vision.pairing import ExactPairer
from cyborg.vision.sources import SourceOptions, camera_index, open_source

JAZZY = get_typestore(Stores.ROS2_JAZZY)
NOETIC = get_typestore(Stores.ROS1_NOETIC)
IMAGE, COMPRESSED = "sensor_msgs/msg/Image", "sensor_msgs/msg/CompressedImage"
STRING = "std_msgs/msg/String"
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


# --------------------------------------------------------------------------- image files


def test_image_source_reads_bgr_with_right_image_and_npy_depth(tmp_path: Path) -> None:
    left, right = texture(12, 16, 1), texture(12, 16, 2)
    depth = np.random.default_rng(3).uniform(0.3, 9.0, (12, 16)).astype(np.float32)
    depth[0, 0] = np.nan
    source = ImageSource(write_image(tmp_path / "left.png", left),
                         right=write_image(tmp_path / "right.png", right),
                         depth=write_npy(tmp_path / "depth.npy", depth))
    assert source.length == 1
    [frame] = frames_of(source)
    assert frame.left.dtype == np.uint8 and frame.left.shape == (12, 16, 3)
    np.testing.assert_array_equal(frame.left, left)
    assert frame.right is not None
    np.testing.assert_array_equal(frame.right, right)
    same_depth(frame.depth, depth)
    assert (frame.index, frame.stamp_ns, frame.size) == (0, 0, (16, 12))
    assert source.dropped == 0


def test_image_source_can_be_read_twice(tmp_path: Path) -> None:
    source = ImageSource(write_image(tmp_path / "a.png", texture(4, 4, 0)))
    assert len(list(source)) == len(list(source)) == 1


def test_depth_png_in_millimetres_becomes_metres_with_zero_as_nan(tmp_path: Path) -> None:
    millimetres = np.array([[0, 1500, 65535], [250, 0, 1]], dtype=np.uint16)
    write_image(tmp_path / "depth.png", millimetres)
    [frame] = frames_of(ImageSource(write_image(tmp_path / "image.png", texture(2, 3, 0)),
                                    depth=tmp_path / "depth.png"))
    same_depth(frame.depth, np.array([[np.nan, 1.5, 65.535], [0.25, np.nan, 0.001]]))


def test_depth_npz_and_float64_npy_are_read_as_float32_metres(tmp_path: Path) -> None:
    metres = np.array([[1.25, 2.5], [np.nan, np.inf]])
    np.savez(tmp_path / "d.npz", depth=metres)
    write_npy(tmp_path / "d.npy", metres)  # float64
    shutil.copy(tmp_path / "d.npy", tmp_path / "UPPER.NPY")
    image = write_image(tmp_path / "i.png", texture(2, 2, 0))
    for name in ("d.npz", "d.npy", "UPPER.NPY"):
        [frame] = frames_of(ImageSource(image, depth=tmp_path / name))
        same_depth(frame.depth, metres)


def test_grey_bgra_and_16_bit_images_become_bgr_uint8(tmp_path: Path) -> None:
    grey = np.arange(12, dtype=np.uint8).reshape(3, 4) * 20
    bgra = np.dstack([texture(3, 4, 5), np.full((3, 4), 7, np.uint8)])
    deep = (texture(3, 4, 6).astype(np.uint16) << 8) | 0xFF
    [from_grey] = frames_of(ImageSource(write_image(tmp_path / "grey.png", grey)))
    [from_bgra] = frames_of(ImageSource(write_image(tmp_path / "bgra.png", bgra)))
    [from_deep] = frames_of(ImageSource(write_image(tmp_path / "deep.png", deep)))
    np.testing.assert_array_equal(from_grey.left, np.dstack([grey] * 3))
    np.testing.assert_array_equal(from_bgra.left, bgra[:, :, :3])
    np.testing.assert_array_equal(from_deep.left, texture(3, 4, 6))


def test_side_by_side_image_splits_into_left_and_right_halves(tmp_path: Path) -> None:
    left, right = texture(6, 5, 1), texture(6, 5, 2)
    path = write_image(tmp_path / "zed.png", np.hstack([left, right]))
    [frame] = frames_of(ImageSource(path, side_by_side=True))
    np.testing.assert_array_equal(frame.left, left)
    assert frame.right is not None
    np.testing.assert_array_equal(frame.right, right)
    assert frame.left.flags.c_contiguous and frame.right.flags.c_contiguous


def test_side_by_side_image_of_odd_width_is_refused(tmp_path: Path) -> None:
    path = write_image(tmp_path / "odd.png", texture(4, 9, 0))
    with pytest.raises(VisionError, match=r"odd\.png.*even width, not 9"):
        list(ImageSource(path, side_by_side=True))


def test_image_named_by_nanoseconds_takes_its_stamp(tmp_path: Path) -> None:
    [frame] = frames_of(ImageSource(write_image(tmp_path / f"{T0}.png", texture(2, 2, 0))))
    assert frame.stamp_ns == T0


# --------------------------------------------------------------------------- folders


def test_folder_gives_images_in_name_order_stamped_by_rate(tmp_path: Path) -> None:
    for value, name in ((30, "0003"), (10, "0001"), (20, "0002")):
        write_image(tmp_path / f"{name}.png", np.full((2, 3, 3), value, np.uint8))
    (tmp_path / "notes.txt").write_text("not an image")
    source = FolderSource(tmp_path, rate=10.0)
    frames = frames_of(source)
    assert source.length == 3 and source.dropped == 0
    assert [int(frame.left[0, 0, 0]) for frame in frames] == [10, 20, 30]
    assert [frame.stamp_ns for frame in frames] == [0, 100_000_000, 200_000_000]
    assert [frame.index for frame in frames] == [0, 1, 2]
    assert all(frame.right is None and frame.depth is None for frame in frames)


def test_folder_stamps_from_nanosecond_file_names(tmp_path: Path) -> None:
    stamps = [T0 + 33_333_333 * k for k in range(3)]
    for stamp in stamps:
        write_image(tmp_path / f"{stamp}.jpg", texture(2, 2, 0))
    write_image(tmp_path / f"{'²' * 16}.png", texture(2, 2, 0))  # digits, but not ASCII ones
    frames = frames_of(FolderSource(tmp_path, rate=10.0))
    assert [frame.stamp_ns for frame in frames] == [*stamps, 300_000_000]


def test_folder_pairs_left_right_and_depth_by_name_and_counts_the_unpaired(
        tmp_path: Path) -> None:
    for name in ("a", "b", "c", "d"):
        write_image(tmp_path / "left" / f"{name}.png", texture(4, 5, ord(name)))
    for name in ("a", "b", "c", "d"):
        write_image(tmp_path / "right" / f"{name}.png", texture(4, 5, ord(name) + 100))
    for name in ("a", "c", "e"):  # b and d have no depth; e has no image
        write_npy(tmp_path / "depth" / f"{name}.npy", np.full((4, 5), ord(name), np.float32))
    source = FolderSource(tmp_path)
    frames = frames_of(source)
    assert source.names == ["a", "c"] and source.length == 2
    # left b, d; right b, d (their pairs lost their depth); depth e
    assert source.dropped == 5
    for frame, name in zip(frames, "ac", strict=True):
        np.testing.assert_array_equal(frame.left, texture(4, 5, ord(name)))
        assert frame.right is not None
        np.testing.assert_array_equal(frame.right, texture(4, 5, ord(name) + 100))
        same_depth(frame.depth, np.full((4, 5), ord(name), np.float32))


def test_folder_with_depth_only_drops_image_without_depth_and_depth_without_image(
        tmp_path: Path) -> None:
    for name in ("01", "02", "03"):
        write_image(tmp_path / f"{name}.png", texture(3, 3, int(name)))
    for name in ("01", "03", "04"):
        write_image(tmp_path / "depth" / f"{name}.png", np.full((3, 3), 2000, np.uint16))
    source = FolderSource(tmp_path)
    frames = frames_of(source)
    assert [frame.index for frame in frames] == [0, 1]
    np.testing.assert_array_equal(frames[1].left, texture(3, 3, 3))
    same_depth(frames[1].depth, np.full((3, 3), 2.0))
    assert source.dropped == 2


def test_folder_errors(tmp_path: Path) -> None:
    with pytest.raises(VisionError, match="not found"):
        FolderSource(tmp_path / "nowhere")
    (tmp_path / "empty").mkdir()
    with pytest.raises(VisionError, match="empty: no images"):
        FolderSource(tmp_path / "empty")
    write_image(tmp_path / "one" / "1.png", texture(2, 2, 0))
    with pytest.raises(VisionError, match="rate must be positive"):
        FolderSource(tmp_path / "one", rate=0.0)
    # frames are paired by name: two images of one name cannot both be frame "1"
    write_image(tmp_path / "one" / "1.jpg", texture(2, 2, 1))
    with pytest.raises(VisionError, match=r"one: 1\.jpg and 1\.png have the same name"):
        FolderSource(tmp_path / "one")


# --------------------------------------------------------------------------- videos


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


@pytest.mark.parametrize("suffix", [".avi", ".mp4"])
def test_video_frames_with_increasing_stamps(tmp_path: Path, suffix: str) -> None:
    levels = [0, 50, 100, 150, 200]
    source = VideoSource(write_video(tmp_path / f"ride{suffix}", grey_levels(levels)))
    assert source.length == 5
    frames = frames_of(source)
    assert len(frames) == 5 and [frame.index for frame in frames] == list(range(5))
    for level, mean in zip(levels, mean_levels([frame.left for frame in frames]), strict=True):
        assert abs(level - mean) <= 4
    stamps = [frame.stamp_ns for frame in frames]
    assert stamps[0] == 0
    np.testing.assert_allclose(np.diff(stamps), 100_000_000, rtol=0.01)  # 10 frames/s
    assert not source.capture.isOpened()  # closed by the with block


def test_stereo_pair_of_videos(tmp_path: Path) -> None:
    left = write_video(tmp_path / "left.avi", grey_levels([20, 40, 60, 80]))
    right = write_video(tmp_path / "right.avi", grey_levels([200, 220, 240]))
    source = VideoSource(left, right=right)
    assert source.length == 3  # the shorter of the two
    frames = frames_of(source)
    assert mean_levels([frame.left for frame in frames]) == pytest.approx([20, 40, 60], abs=4)
    rights = [frame.right for frame in frames if frame.right is not None]
    assert mean_levels(rights) == pytest.approx([200, 220, 240], abs=4)


@pytest.mark.parametrize("suffix", [".avi", ".mp4"])
def test_a_video_plays_from_the_start_each_time_it_is_iterated(tmp_path: Path,
                                                               suffix: str) -> None:
    left = write_video(tmp_path / f"left{suffix}", grey_levels([20, 40, 60]))
    right = write_video(tmp_path / f"right{suffix}", grey_levels([200, 220, 240]))
    source = VideoSource(left, right=right)
    first = list(source.frames())
    again = list(source.frames())
    source.close()
    assert [frame.stamp_ns for frame in again] == [frame.stamp_ns for frame in first]
    assert mean_levels([frame.left for frame in again]) == pytest.approx([20, 40, 60], abs=4)
    rights = [frame.right for frame in again if frame.right is not None]
    assert mean_levels(rights) == pytest.approx([200, 220, 240], abs=4)


def test_side_by_side_video_splits_each_frame(tmp_path: Path) -> None:
    packed = [np.hstack([np.full((32, 32, 3), 30, np.uint8), np.full((32, 32, 3), 220,
                                                                     np.uint8)])] * 2
    frames = frames_of(VideoSource(write_video(tmp_path / "zed.avi", packed),
                                   side_by_side=True))
    assert len(frames) == 2
    for frame in frames:
        assert frame.size == (32, 32) and frame.right is not None
        assert abs(float(frame.left.mean()) - 30) < 4
        assert abs(float(frame.right.mean()) - 220) < 4


def test_missing_and_unreadable_videos_are_named(tmp_path: Path) -> None:
    with pytest.raises(VisionError, match=r"video .*gone\.mp4: not found"):
        VideoSource(tmp_path / "gone.mp4")
    text = tmp_path / "notes.mp4"
    text.write_text("this is not a video\n" * 20)
    with pytest.raises(VisionError, match=r"notes\.mp4: cannot be opened"):
        VideoSource(text)
    left = write_video(tmp_path / "left.avi", grey_levels([1]))
    with pytest.raises(VisionError, match=r"missing\.avi: not found"):
        VideoSource(left, right=tmp_path / "missing.avi")


# --------------------------------------------------------------------------- bags


@dataclass
class Message:
    topic: str
    msgtype: str
    stamp: int
    message: Any


@dataclass
class Bag:
    """Messages for a bag, written in list order with increasing receive times."""

    messages: list[Message] = field(default_factory=list)

    def write(self, path: Path, kind: str) -> Path:
        if kind == "ros1":
            with Writer1(path) as writer:
                connections1 = {}
                for item in self.messages:
                    if item.topic not in connections1:
                        connections1[item.topic] = writer.add_connection(
                            item.topic, item.msgtype, typestore=NOETIC)
                    writer.write(connections1[item.topic], item.stamp + 1000,
                                 NOETIC.serialize_ros1(item.message, item.msgtype))
            return path
        plugin = {"sqlite3": StoragePlugin.SQLITE3, "mcap": StoragePlugin.MCAP}[kind]
        with Writer2(path, version=9, storage_plugin=plugin) as writer2:
            connections2 = {}
            for item in self.messages:
                if item.topic not in connections2:
                    connections2[item.topic] = writer2.add_connection(
                        item.topic, item.msgtype, typestore=JAZZY)
                writer2.write(connections2[item.topic], item.stamp + 1000,
                              JAZZY.serialize_cdr(item.message, item.msgtype))
        return path


def ros_header(store: Typestore, stamp: int, frame_id: str) -> Any:
    time = store.types["builtin_interfaces/msg/Time"](sec=stamp // 1_000_000_000,
                                                      nanosec=stamp % 1_000_000_000)
    if store is NOETIC:
        return store.types["std_msgs/msg/Header"](seq=0, stamp=time, frame_id=frame_id)
    return store.types["std_msgs/msg/Header"](stamp=time, frame_id=frame_id)


def image_message(store: Typestore, stamp: int, pixels: np.ndarray, encoding: str,
                  frame_id: str = "camera_left", is_bigendian: int = 0) -> Any:
    height = pixels.shape[0]
    data = np.ascontiguousarray(pixels).reshape(-1).view(np.uint8)
    return store.types[IMAGE](header=ros_header(store, stamp, frame_id), height=height,
                              width=pixels.shape[1], encoding=encoding,
                              is_bigendian=is_bigendian, step=data.size // height, data=data)


def compressed_message(store: Typestore, stamp: int, image: np.ndarray) -> Any:
    ok, encoded = cv2.imencode(".jpg", image, [cv2.IMWRITE_JPEG_QUALITY, 95])
    assert ok
    return store.types[COMPRESSED](header=ros_header(store, stamp, "camera"), format="jpeg",
                                   data=encoded.reshape(-1))


STAMPS = [T0 + 50_000_000 * k for k in range(4)]
COLOUR_TOPIC, DEPTH_TOPIC = "/camera/color/image_raw", "/camera/depth/image_raw"


@dataclass
class Expected:
    images: dict[int, np.ndarray]
    depths: dict[int, np.ndarray]


def camera_bag(store: Typestore, colour: str, depth: str) -> tuple[Bag, Expected]:
    """Images at stamps 0, 1, 3 and depth at 0, 2, 3: frames 0 and 3; image 1 and depth 2
    are unpaired. Frame 0 is completed by its depth map, frame 3 by its image."""
    rng = np.random.default_rng(7)
    images = {k: texture(6, 8, 10 + k) for k in (0, 1, 3)}
    metres = {k: rng.uniform(0.5, 6.0, (6, 8)).astype(np.float32) for k in (0, 2, 3)}
    depth_data: dict[int, np.ndarray] = {}
    for k, value in metres.items():
        if depth == "16UC1":
            millimetres = np.round(value * 1000).astype(np.uint16)
            millimetres[1, 2] = 0
            depth_data[k] = millimetres
            metres[k] = depth_in_metres(millimetres)
        else:
            value[1, 2] = np.nan
            depth_data[k] = value

    def colour_message(k: int) -> Message:
        pixels = images[k] if colour == "bgr8" else images[k][:, :, ::-1]
        return Message(COLOUR_TOPIC, IMAGE, STAMPS[k],
                       image_message(store, STAMPS[k], pixels, colour))

    def depth_message(k: int) -> Message:
        return Message(DEPTH_TOPIC, IMAGE, STAMPS[k],
                       image_message(store, STAMPS[k], depth_data[k], depth, "camera_depth"))

    chatter = Message("/chatter", STRING, STAMPS[0], store.types[STRING](data="hello"))
    bag = Bag([chatter, colour_message(0), depth_message(0), colour_message(1),
               depth_message(2), depth_message(3), colour_message(3)])
    return bag, Expected({0: images[0], 3: images[3]}, {0: metres[0], 3: metres[3]})


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


# --------------------------------------------------------------------------- open_source


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


# --------------------------------------------------------------------------- bad input


def test_corrupt_and_truncated_images_are_named(tmp_path: Path) -> None:
    noise = tmp_path / "noise.png"
    noise.write_bytes(np.random.default_rng(1).bytes(400))
    whole = cv2.imencode(".png", texture(20, 20, 0))[1].tobytes()
    truncated = tmp_path / "truncated.png"
    truncated.write_bytes(whole[: len(whole) // 2])
    for path in (noise, truncated):
        with pytest.raises(VisionError, match=rf"image .*{path.name}: cannot be decoded"):
            ImageSource(path)
    with pytest.raises(VisionError, match="is a folder"):
        ImageSource(tmp_path)
    write_image(tmp_path / "folder" / "0.png", texture(2, 2, 0))
    noise.rename(tmp_path / "folder" / "1.png")
    with pytest.raises(VisionError, match=r"1\.png: cannot be decoded"):
        frames_of(FolderSource(tmp_path / "folder"))


def test_depth_map_of_another_size_is_refused(tmp_path: Path) -> None:
    image = write_image(tmp_path / "image.png", texture(4, 6, 0))
    depth = write_npy(tmp_path / "depth.npy", np.ones((6, 4), np.float32))
    with pytest.raises(VisionError, match=r"image\.png: depth map is 4x6 but the image is 6x4"):
        frames_of(ImageSource(image, depth=depth))


def test_depth_maps_of_wrong_type_are_refused(tmp_path: Path) -> None:
    image = write_image(tmp_path / "image.png", texture(2, 2, 0))
    cases = {"int.npy": r"int32: depth must be float32 metres or uint16",
             "grey.png": r"uint8 pixels",
             "cube.npy": r"must be a 2-D array",
             "broken.npy": r"not a readable numpy array",
             "objects.npy": r"not a readable numpy array"}
    write_npy(tmp_path / "int.npy", np.ones((2, 2), np.int32))
    write_image(tmp_path / "grey.png", np.ones((2, 2), np.uint8))
    write_npy(tmp_path / "cube.npy", np.ones((2, 2, 2), np.float32))
    (tmp_path / "broken.npy").write_bytes(b"\x93NUMPY garbage")
    np.save(tmp_path / "objects.npy", np.array([[None, 1]], dtype=object), allow_pickle=True)
    for name, message in cases.items():
        with pytest.raises(VisionError, match=message):
            frames_of(ImageSource(image, depth=tmp_path / name))


def test_big_endian_depth_npy_is_read(tmp_path: Path) -> None:
    image = write_image(tmp_path / "image.png", texture(1, 2, 0))
    write_npy(tmp_path / "depth.npy", np.array([[0, 1250]], dtype=">u2"))
    [frame] = frames_of(ImageSource(image, depth=tmp_path / "depth.npy"))
    same_depth(frame.depth, np.array([[np.nan, 1.25]]))


# --------------------------------------------------------------------------- messages


@pytest.fixture(scope="module")
def types() -> MessageTypes:
    return MessageTypes()


def test_bgr8_round_trip_shares_memory(types: MessageTypes) -> None:
    image = texture(5, 7, 0)
    message = bgr_to_image(types, image, T0, "cam")
    assert (message.encoding, message.step, message.header.stamp.nanosec) == \
        ("bgr8", 21, T0 % 1_000_000_000)
    back = image_to_bgr(message)
    assert np.shares_memory(back, image)
    np.testing.assert_array_equal(back, image)
    raw = types.deserialize(types.serialize(message, IMAGE), IMAGE)
    np.testing.assert_array_equal(image_to_bgr(raw), image)


def test_colour_encodings(types: MessageTypes) -> None:
    image = texture(3, 4, 1)
    rgba = np.dstack([image[:, :, ::-1], np.full((3, 4), 9, np.uint8)])
    for encoding, pixels in (("rgb8", image[:, :, ::-1]), ("bgra8", np.dstack(
            [image, np.zeros((3, 4), np.uint8)])), ("rgba8", rgba), ("8UC3", image)):
        np.testing.assert_array_equal(image_to_bgr(image_message(JAZZY, T0, pixels, encoding)),
                                      image, err_msg=encoding)
    grey = image[:, :, 0]
    np.testing.assert_array_equal(image_to_bgr(image_message(JAZZY, T0, grey, "mono8")),
                                  np.dstack([grey] * 3))


def test_depth_round_trip_and_millimetres(types: MessageTypes) -> None:
    metres = np.array([[0.5, np.nan, np.inf], [2.25, -np.inf, 7.0]], np.float32)
    message = depth_to_image(types, metres, T0, "cam")
    assert (message.encoding, message.step) == ("32FC1", 12)
    same_depth(image_to_depth(message), metres)
    raw = types.deserialize(types.serialize(message, IMAGE), IMAGE)
    same_depth(image_to_depth(raw), metres)
    millimetres = np.array([[0, 1000, 2500]], np.uint16)
    for encoding in ("16UC1", "mono16"):
        same_depth(image_to_depth(image_message(JAZZY, T0, millimetres, encoding)),
                   np.array([[np.nan, 1.0, 2.5]]))
    big = image_message(JAZZY, T0, millimetres.astype(">u2"), "16UC1", is_bigendian=1)
    same_depth(image_to_depth(big), np.array([[np.nan, 1.0, 2.5]]))


def test_padded_rows_are_read(types: MessageTypes) -> None:
    image = texture(3, 5, 2)
    padded = np.full((3, 15 + 9), 0xEE, np.uint8)  # 9 junk bytes after each row
    padded[:, :15] = image.reshape(3, 15)
    message = image_message(JAZZY, T0, image, "bgr8")
    message.step, message.data = 24, padded.reshape(-1)
    np.testing.assert_array_equal(image_to_bgr(message), image)
    message.data = padded.reshape(-1)[:-9]  # the last row's padding may be left out
    np.testing.assert_array_equal(image_to_bgr(message), image)
    metres = np.array([[1.0, 2.0], [3.0, 4.0]], np.float32)
    rows = np.zeros((2, 12), np.uint8)
    rows[:, :8] = metres.view(np.uint8).reshape(2, 8)
    depth = image_message(JAZZY, T0, metres, "32FC1")
    depth.step, depth.data = 12, rows.reshape(-1)
    same_depth(image_to_depth(depth), metres)


def test_message_data_as_bytes(types: MessageTypes) -> None:
    image = texture(2, 3, 3)
    message = image_message(JAZZY, T0, image, "bgr8")
    message.data = image.tobytes()
    np.testing.assert_array_equal(image_to_bgr(message), image)
    jpeg = compressed_message(JAZZY, T0, np.full((8, 8, 3), 128, np.uint8))
    jpeg.data = jpeg.data.tobytes()
    assert np.abs(compressed_to_bgr(jpeg).astype(int) - 128).max() <= 2


def test_bad_messages_name_their_topic(types: MessageTypes) -> None:
    message = image_message(JAZZY, T0, texture(4, 4, 0), "bgr8")
    message.data = message.data[:-1]
    with pytest.raises(VisionError, match=r"/cam/left: image of 4x4 bgr8 .*needs 48 .* 47"):
        image_to_bgr(message, "/cam/left")
    message = image_message(JAZZY, T0, texture(4, 4, 0), "bgr8")
    message.step = 6  # shorter than a row
    with pytest.raises(VisionError, match="/cam/left"):
        image_to_bgr(message, "/cam/left")
    message.step, message.encoding = 12, "yuv422"
    with pytest.raises(VisionError, match=r"/cam/left: image encoding 'yuv422'"):
        image_to_bgr(message, "/cam/left")
    with pytest.raises(VisionError, match=r"/cam/depth: depth encoding 'bgr8'"):
        image_to_depth(image_message(JAZZY, T0, texture(2, 2, 0), "bgr8"), "/cam/depth")
    garbage = compressed_message(JAZZY, T0, texture(4, 4, 0))
    garbage.data = np.frombuffer(b"not a jpeg", np.uint8)
    with pytest.raises(VisionError, match=r"/cam/jpeg: compressed image \(jpeg, 10 bytes\)"):
        compressed_to_bgr(garbage, "/cam/jpeg")
    with pytest.raises(VisionError, match="BGR uint8"):
        bgr_to_image(types, np.zeros((4, 4), np.uint8), T0, "cam")
    with pytest.raises(VisionError, match="2-D"):
        depth_to_image(types, np.zeros((4, 4, 3), np.float32), T0, "cam")


# --------------------------------------------------------------------------- pairing


def test_pairer_returns_the_complete_set() -> None:
    pairer = ExactPairer(("image", "depth"))
    assert pairer.add("image", 10, "i10") is None
    assert pairer.add("depth", 10, "d10") == {"image": "i10", "depth": "d10"}
    assert pairer.add("depth", 20, "d20") is None
    assert pairer.add("image", 20, "i20") == {"image": "i20", "depth": "d20"}
    assert pairer.dropped == 0 and not pairer.pending


def test_pairer_drops_what_a_newer_pair_overtook_and_what_is_left_at_the_end() -> None:
    pairer = ExactPairer(("image", "depth"))
    pairer.add("image", 1, "i1")
    pairer.add("depth", 2, "d2")
    pairer.add("image", 5, "i5")
    assert pairer.add("depth", 3, "d3") is None
    assert pairer.add("depth", 4, "d4") is None
    assert pairer.add("image", 3, "i3") == {"image": "i3", "depth": "d3"}
    assert pairer.dropped == 2  # i1, d2
    assert list(pairer.pending) == [5, 4]
    pairer.finish()
    assert pairer.dropped == 4 and not pairer.pending


def test_pairer_keeps_the_newer_of_two_items_of_one_stamp() -> None:
    pairer = ExactPairer(("image", "depth"))
    pairer.add("image", 1, "first")
    pairer.add("image", 1, "second")
    assert pairer.add("depth", 1, "d") == {"image": "second", "depth": "d"}
    assert pairer.dropped == 1


def test_pairer_bounds_what_waits() -> None:
    pairer = ExactPairer(("image", "depth", "right"), max_pending=3)
    for stamp in range(5):
        pairer.add("image", stamp, stamp)
    pairer.add("depth", 4, "d4")
    assert list(pairer.pending) == [2, 3, 4] and pairer.dropped == 2
    pairer.add("right", 2, "r2")
    assert pairer.add("depth", 2, "d2") == {"image": 2, "right": "r2", "depth": "d2"}
    assert list(pairer.pending) == [3, 4]
    pairer.finish()
    assert pairer.dropped == 2 + 3  # image 3, image 4 and depth 4


def test_pairer_of_one_stream_and_bad_streams() -> None:
    pairer = ExactPairer(("image",))
    assert pairer.add("image", 1, "a") == {"image": "a"}
    with pytest.raises(KeyError, match="unknown stream 'depth'"):
        pairer.add("depth", 1, "b")
    for streams in ((), ("image", "image")):
        with pytest.raises(ValueError, match="distinct"):
            ExactPairer(streams)


@settings(max_examples=60, deadline=None)
@given(items=st.lists(st.tuples(st.sampled_from(["image", "depth", "right"]),
                                st.integers(0, 8)), max_size=40),
       max_pending=st.integers(1, 5), stereo=st.booleans())
def test_pairer_accounts_for_every_item(items: list[tuple[str, int]], max_pending: int,
                                        stereo: bool) -> None:
    streams = ("image", "depth", "right") if stereo else ("image", "depth")
    items = [(stream, stamp) for stream, stamp in items if stream in streams]
    pairer = ExactPairer(streams, max_pending=max_pending)
    returned = 0
    for serial, (stream, stamp) in enumerate(items):
        complete = pairer.add(stream, stamp, (stream, stamp, serial))
        assert len(pairer.pending) <= max_pending
        if complete is not None:
            assert sorted(complete) == sorted(streams)
            assert all(item[:2] == (name, stamp) for name, item in complete.items())
            assert complete[stream][2] == serial  # the item just added completed it
            returned += len(complete)
        waiting = sum(len(group) for group in pairer.pending.values())
        assert returned + pairer.dropped + waiting == serial + 1
    pairer.finish()
    assert returned + pairer.dropped == len(items)


@settings(max_examples=20, deadline=None)
@given(stamps=st.lists(st.integers(0, 10**18), unique=True, max_size=20).map(sorted),
       depth_first=st.lists(st.booleans(), min_size=20, max_size=20))
def test_pairer_loses_nothing_of_complete_streams(stamps: list[int],
                                                 depth_first: list[bool]) -> None:
    pairer = ExactPairer(("image", "depth"), max_pending=2)
    paired = []
    for stamp, depth_leads in zip(stamps, depth_first, strict=False):
        order = ("depth", "image") if depth_leads else ("image", "depth")
        assert pairer.add(order[0], stamp, stamp) is None
        complete = pairer.add(order[1], stamp, stamp)
        assert complete == {"image": stamp, "depth": stamp}
        paired.append(stamp)
    pairer.finish()
    assert paired == stamps and pairer.dropped == 0


# --------------------------------------------------------------------------- depth


def test_depth_in_metres() -> None:
    millimetres = np.array([[0, 1, 1234], [65535, 500, 0]], np.uint16)
    same_depth(depth_in_metres(millimetres),
               np.array([[np.nan, 0.001, 1.234], [65.535, 0.5, np.nan]]))
    metres64 = np.array([[1.5, np.nan], [np.inf, -np.inf]])
    converted = depth_in_metres(metres64)
    assert converted.dtype == np.float32
    np.testing.assert_array_equal(converted, metres64.astype(np.float32))
    metres32 = np.ones((2, 2), np.float32)
    assert depth_in_metres(metres32) is metres32  # no copy of what is already right
    for bad in (np.ones((2, 2), np.int32), np.ones((2, 2), np.uint8),
                np.ones((2, 2), np.float16)):
        with pytest.raises(VisionError, match=f"the depth has type {bad.dtype}"):
            depth_in_metres(bad, "the depth")
    with pytest.raises(VisionError, match="2-D"):
        depth_in_metres(np.ones(4, np.float32))


def test_depth_from_disparity() -> None:
    calibration = StereoCalibration(focal_px=700.0, baseline_m=0.12)
    disparity = np.array([[84.0, 42.0, 0.0], [-3.0, np.nan, np.inf]], np.float32)
    depth = calibration.depth_from_disparity(disparity)
    np.testing.assert_allclose(depth[0, :2], [1.0, 2.0], rtol=1e-6)
    assert np.isnan(depth[0, 2]) and np.isnan(depth[1]).all()
    shifted = StereoCalibration(focal_px=700.0, baseline_m=0.12, doffs_px=16.0)
    np.testing.assert_allclose(shifted.depth_from_disparity(np.array([[68.0]])), [[1.0]],
                               rtol=1e-6)
    behind = StereoCalibration(focal_px=700.0, baseline_m=0.12, doffs_px=-16.0)
    depth = behind.depth_from_disparity(np.array([[100.0, 16.0, 10.0]]))
    np.testing.assert_allclose(depth[0, 0], 1.0, rtol=1e-6)
    assert np.isnan(depth[0, 1:]).all()  # d + doffs <= 0: no depth, never a negative one
    for focal, baseline in ((0.0, 0.1), (500.0, -0.1), (float("nan"), 0.1)):
        with pytest.raises(VisionError, match="positive focal length and baseline"):
            StereoCalibration(focal_px=focal, baseline_m=baseline)


def shifted_pair(height: int, width: int, background: int, near: int,
                 box: tuple[int, int, int, int]) -> tuple[np.ndarray, np.ndarray]:
    """A rectified pair: the background ``background`` pixels apart, a box ``near`` apart.

    A point at column ``x`` of the left image is at ``x - disparity`` in the right one.
    """
    far = cv2.GaussianBlur(texture(height, width + background, 11), (3, 3), 0)
    close = cv2.GaussianBlur(texture(height, width, 12), (3, 3), 0)
    top, bottom, x0, x1 = box
    left = far[:, :width].copy()
    left[top:bottom, x0:x1] = close[top:bottom, x0:x1]
    right = far[:, background:width + background].copy()
    right[top:bottom, x0 - near:x1 - near] = close[top:bottom, x0:x1]
    return left, right


def test_stereo_depth_of_a_synthetic_pair() -> None:
    calibration = StereoCalibration(focal_px=500.0, baseline_m=0.1)
    box = (40, 90, 100, 160)
    left, right = shifted_pair(120, 200, 8, 24, box)
    stereo = StereoDepth(calibration, max_disparity=64)
    depth = stereo.depth(left, right)
    assert depth.shape == (120, 200) and depth.dtype == np.float32
    top, bottom, x0, x1 = box
    near = float(np.nanmedian(depth[top + 4:bottom - 4, x0 + 4:x1 - 4]))
    assert near == pytest.approx(500.0 * 0.1 / 24, rel=0.02)
    far = float(np.nanmedian(depth[4:top - 4, 70:196]))
    assert far == pytest.approx(500.0 * 0.1 / 8, rel=0.02)
    assert np.isnan(depth[:, :8]).all()  # no match left of the widest disparity


def test_stereo_depth_refuses_bad_input() -> None:
    calibration = StereoCalibration(focal_px=500.0, baseline_m=0.1)
    for bad in (0, 24, -16):
        with pytest.raises(VisionError, match="multiple of 16"):
            StereoDepth(calibration, max_disparity=bad)
    stereo = StereoDepth(calibration)
    with pytest.raises(VisionError, match="different sizes"):
        stereo.depth(texture(8, 8, 0), texture(8, 10, 0))
    with pytest.raises(VisionError, match="right image must be a BGR"):
        stereo.depth(texture(8, 8, 0), np.zeros((8, 8), np.uint8))


# --------------------------------------------------------------------------- frames


def test_frame_checks_what_it_is_given() -> None:
    with pytest.raises(VisionError, match="left image must be a BGR uint8"):
        Frame(0, np.zeros((2, 2), np.uint8))
    with pytest.raises(VisionError, match="stereo pair must have one size"):
        Frame(0, texture(2, 2, 0), right=texture(2, 3, 0))
    with pytest.raises(VisionError, match="float32 array in metres"):
        Frame(0, texture(2, 2, 0), depth=np.ones((2, 2)))
