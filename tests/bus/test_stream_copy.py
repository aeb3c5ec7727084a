"""Large arrays go into shared memory with a streaming copy: same bytes, fewer cache lines."""

from __future__ import annotations

import mmap
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cyborg.bus import MessageTypes
from cyborg.bus.stream_copy import STREAM_MINIMUM, kernel, stream_copy


@pytest.fixture(scope="module")
def types() -> MessageTypes:
    return MessageTypes()


def test_the_streaming_loop_compiles_here() -> None:
    """numba brings llvmlite, so the fast path must exist wherever cyborg is installed."""
    assert kernel() is not None
    assert kernel(keep_source=True) is not None
    assert kernel(keep_source=True) is not kernel()  # two loops: the source kept or passed by


@settings(max_examples=40, deadline=None)
@given(offset=st.integers(0, 130), extra=st.integers(-70, 4096),
       seed=st.integers(0, 2**32 - 1), keep_source=st.booleans())
def test_the_copy_is_exact_at_any_alignment(offset: int, extra: int, seed: int,
                                            keep_source: bool) -> None:
    """The unaligned head, the 64-byte body and the tail together give the source's bytes,
    and nothing outside the destination is touched."""
    size = STREAM_MINIMUM + extra
    source = np.random.default_rng(seed).integers(0, 256, size, dtype=np.uint8)
    shared = mmap.mmap(-1, size + 256)  # page-aligned, like a shared-memory slot
    shared.write(b"\xab" * len(shared))
    with memoryview(shared) as whole, whole[offset:offset + size] as window:
        stream_copy(window, source, keep_source=keep_source)
    assert shared[offset:offset + size] == source.tobytes()
    assert shared[:offset] == b"\xab" * offset
    assert shared[offset + size:] == b"\xab" * (len(shared) - offset - size)
    shared.close()


def test_small_strided_and_wide_sources() -> None:
    image = np.arange(600 * 800 * 3, dtype=np.uint8).reshape(600, 800, 3)
    for source in (image, image[:, ::2], np.arange(10, dtype=np.uint8),
                   np.linspace(0, 1, STREAM_MINIMUM, dtype=np.float32)):
        target = np.zeros(source.nbytes, np.uint8)
        stream_copy(target, source)
        assert target.tobytes() == np.ascontiguousarray(source).tobytes()


def test_a_destination_of_the_wrong_size_is_refused() -> None:
    with pytest.raises(ValueError, match="destination holds 10 bytes, source 11"):
        stream_copy(np.zeros(10, np.uint8), np.zeros(11, np.uint8))


def _image(types: MessageTypes, data: np.ndarray, frame_id: str = "zed_left") -> Any:
    get = types.message_class
    return get("sensor_msgs/msg/Image")(
        header=get("std_msgs/msg/Header")(stamp=get("builtin_interfaces/msg/Time")(
            sec=1, nanosec=2), frame_id=frame_id),
        height=1, width=data.size, encoding="mono8", is_bigendian=0, step=data.size, data=data)


def _float_array(types: MessageTypes, data: np.ndarray) -> Any:
    get = types.message_class
    return get("std_msgs/msg/Float32MultiArray")(
        layout=get("std_msgs/msg/MultiArrayLayout")(dim=[], data_offset=0), data=data)


@pytest.mark.parametrize(("type_name", "build", "data"), [
    ("sensor_msgs/msg/Image", _image, np.arange(STREAM_MINIMUM * 3, dtype=np.uint8)),
    ("sensor_msgs/msg/Image", _image, np.arange(STREAM_MINIMUM + 3, dtype=np.uint8)),
    ("std_msgs/msg/Float32MultiArray", _float_array,
     np.linspace(0, 1, STREAM_MINIMUM // 2, dtype=np.float32)),
    ("sensor_msgs/msg/Image", _image, np.arange(100, dtype=np.uint8)),  # small: rosbags' path
])
@pytest.mark.parametrize("offset", [0, 5, 16])
def test_serialising_into_a_buffer_matches_rosbags(
        types: MessageTypes, type_name: str, build: Any, data: np.ndarray, offset: int) -> None:
    """The big last field is streamed after the rest of the message: byte for byte what
    rosbags writes, at any offset into the buffer, and decoded back to the same values."""
    message = build(types, data)
    expected = bytes(types.serialize(message, type_name))
    size = types.cdr_size(message, type_name)
    buffer = bytearray(offset + size + 8)
    with memoryview(buffer) as whole, whole[offset:] as window:
        assert types.serialize_into(message, type_name, window) == size == len(expected)
    assert bytes(buffer[offset:offset + size]) == expected
    back = types.deserialize(bytes(buffer[offset:offset + size]), type_name)
    assert np.array_equal(back.data, data)


def test_a_non_contiguous_or_foreign_tail_takes_the_ordinary_path(types: MessageTypes) -> None:
    strided = np.arange(STREAM_MINIMUM * 2, dtype=np.uint8)[::2]
    message = _image(types, strided)
    assert types._large_tail(message, "sensor_msgs/msg/Image") is None
    buffer = bytearray(types.cdr_size(message, "sensor_msgs/msg/Image"))
    types.serialize_into(message, "sensor_msgs/msg/Image", memoryview(buffer))
    assert bytes(buffer) == bytes(types.serialize(message, "sensor_msgs/msg/Image"))
    cloud = types.message_class("sensor_msgs/msg/PointCloud2")  # data is not the last field
    assert types._large_tail(cloud(header=message.header, height=1, width=1, fields=[],
                                   is_bigendian=False, point_step=1, row_step=1,
                                   data=np.zeros(STREAM_MINIMUM, np.uint8), is_dense=True),
                             "sensor_msgs/msg/PointCloud2") is None
