"""Camera sources read from files (cyborg.vision.file_sources): images, folders and videos.

An image (with a right image and a depth map, or side by side), a folder of images paired with
right images and depth maps by name, and videos (a stereo pair, or side by side), stamped by
file name or rate. Every input is generated small in ``tmp_path``
(tests/vision/source_fixtures.py).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from cyborg.vision import VisionError
from cyborg.vision.file_sources import FolderSource, ImageSource, VideoSource
from tests.vision.source_fixtures import (
    T0,
    frames_of,
    grey_levels,
    mean_levels,
    same_depth,
    texture,
    write_image,
    write_npy,
    write_video,
)

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
