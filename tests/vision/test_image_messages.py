"""Images and depth maps as ROS messages (cyborg.vision.image_messages), both ways.

BGR images and float32 depth maps to Image messages and back (sharing memory where they can),
colour and depth encodings, padded rows, data given as bytes, compressed JPEG images, and bad
messages refused with errors that name their topic.
"""

from __future__ import annotations

import numpy as np
import pytest

from cyborg.bus.message_types import MessageTypes
from cyborg.vision import VisionError
from cyborg.vision.image_messages import (
    bgr_to_image,
    compressed_to_bgr,
    depth_to_image,
    image_to_bgr,
    image_to_depth,
)
from tests.vision.ros_fixtures import IMAGE, JAZZY, compressed_message, image_message
from tests.vision.source_fixtures import T0, same_depth, texture


@pytest.fixture(scope="module")
def types() -> MessageTypes:
    return MessageTypes()


def test_bgr8_round_trip_shares_memory(types: MessageTypes) -> None:
    image = texture(5, 7, 0)
    message = bgr_to_image(image, T0, "cam")
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
    message = depth_to_image(metres, T0, "cam")
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
        bgr_to_image(np.zeros((4, 4), np.uint8), T0, "cam")
    with pytest.raises(VisionError, match="2-D"):
        depth_to_image(np.zeros((4, 4, 3), np.float32), T0, "cam")
