"""``sensor_msgs/Image`` and ``CompressedImage`` to numpy and back.

Colour images become BGR ``uint8`` (height x width x 3): ``bgr8``, ``rgb8``, ``bgra8``,
``rgba8``, ``mono8`` and ``8UC3`` are read. Depth images become ``float32`` metres following
REP 118: ``32FC1`` is metres, ``16UC1``/``mono16`` millimetres (0 = unknown → NaN). Rows padded
beyond ``width`` (``step`` larger than a row) are handled. Reading gives views where it can.
"""

from __future__ import annotations

from typing import Any

import cv2
import numpy as np

from cyborg.bus.msgs.builtin_interfaces.msg import Time
from cyborg.bus.msgs.sensor_msgs.msg import Image
from cyborg.bus.msgs.std_msgs.msg import Header
from cyborg.vision.depth import depth_in_metres
from cyborg.vision.frames import VisionError, check_image

_COLOUR = {"bgr8": (3, None), "8UC3": (3, None), "rgb8": (3, cv2.COLOR_RGB2BGR),
           "bgra8": (4, cv2.COLOR_BGRA2BGR), "rgba8": (4, cv2.COLOR_RGBA2BGR),
           "mono8": (1, cv2.COLOR_GRAY2BGR), "8UC1": (1, cv2.COLOR_GRAY2BGR)}
_DEPTH: dict[str, np.dtype[Any]] = {"32FC1": np.dtype("<f4"), "16UC1": np.dtype("<u2"),
                                    "mono16": np.dtype("<u2")}


def stamp_ns(header: Any) -> int:
    """A ``std_msgs/Header``'s stamp in nanoseconds (since the epoch, or of simulated time)."""
    return int(header.stamp.sec) * 1_000_000_000 + int(header.stamp.nanosec)


def _bytes(data: Any) -> np.ndarray:
    """A message's ``uint8[]`` field as a flat ``uint8`` array.

    The field is a numpy array (as rosbags and the bus deserialise it) or ``bytes``, which
    ``np.asarray`` would try to parse as a number.
    """
    if isinstance(data, bytes | bytearray | memoryview):
        return np.frombuffer(data, dtype=np.uint8)
    return np.asarray(data, dtype=np.uint8).reshape(-1)


def _rows(message: Any, dtype: np.dtype, channels: int, topic: str) -> np.ndarray:
    height, width, step = int(message.height), int(message.width), int(message.step)
    row_bytes = width * channels * dtype.itemsize
    data = _bytes(message.data)
    if height == 0 or width == 0 or step < row_bytes or data.size < step * (height - 1) \
            + row_bytes:
        raise VisionError(f"{topic}: image of {width}x{height} {message.encoding} with step "
                          f"{step} needs {step * height} bytes, the message has {data.size}")
    if getattr(message, "is_bigendian", 0) and dtype.itemsize > 1:
        dtype = dtype.newbyteorder(">")
    if step == row_bytes:
        pixels = data[: height * step].view(dtype)
    else:
        padded = np.lib.stride_tricks.as_strided(data, (height, row_bytes), (step, 1))
        pixels = np.ascontiguousarray(padded).reshape(-1).view(dtype)
    shape = (height, width, channels) if channels > 1 else (height, width)
    return pixels.reshape(shape)


def image_to_bgr(message: Any, topic: str = "image") -> np.ndarray:
    """A colour ``sensor_msgs/Image`` as a BGR ``uint8`` array (a view for ``bgr8``)."""
    encoding = str(message.encoding)
    if encoding not in _COLOUR:
        raise VisionError(f"{topic}: image encoding {encoding!r} is not a colour encoding "
                          f"({', '.join(_COLOUR)})")
    channels, conversion = _COLOUR[encoding]
    pixels = _rows(message, np.dtype(np.uint8), channels, topic)
    return pixels if conversion is None else cv2.cvtColor(pixels, conversion)


def image_to_depth(message: Any, topic: str = "depth") -> np.ndarray:
    """A depth ``sensor_msgs/Image`` as ``float32`` metres (NaN where unknown)."""
    encoding = str(message.encoding)
    if encoding not in _DEPTH:
        raise VisionError(f"{topic}: depth encoding {encoding!r}; expected 32FC1 (metres) "
                          "or 16UC1 (millimetres)")
    return depth_in_metres(np.asarray(_rows(message, _DEPTH[encoding], 1, topic)).astype(
        _DEPTH[encoding].newbyteorder("="), copy=False), topic)


def compressed_to_bgr(message: Any, topic: str = "image") -> np.ndarray:
    """A ``sensor_msgs/CompressedImage`` (JPEG, PNG) decoded to BGR."""
    data = _bytes(message.data)
    image = cv2.imdecode(data, cv2.IMREAD_COLOR) if data.size else None
    if image is None:
        raise VisionError(f"{topic}: compressed image ({message.format or 'no format'}, "
                          f"{data.size} bytes) cannot be decoded")
    return image


def header(stamp: int, frame_id: str) -> Header:
    """A ``std_msgs/Header`` stamped ``stamp`` (nanoseconds) in ``frame_id``."""
    return Header(stamp=Time(sec=stamp // 1_000_000_000, nanosec=stamp % 1_000_000_000),
                  frame_id=frame_id)


def bgr_to_image(image: np.ndarray, stamp: int, frame_id: str) -> Image:
    """A ``bgr8`` ``sensor_msgs/Image`` sharing ``image``'s memory when it is contiguous.

    ``stamp`` is in nanoseconds. Raises
    :class:`~cyborg.vision.frames.VisionError` for an image that is not BGR.
    """
    check_image(image, "image")  # a grey image would give a message whose step lies
    pixels = np.ascontiguousarray(image)
    height, width = pixels.shape[:2]
    return Image(
        header=header(stamp, frame_id), height=height, width=width, encoding="bgr8",
        is_bigendian=0, step=width * 3, data=pixels.reshape(-1))


def depth_to_image(depth: np.ndarray, stamp: int, frame_id: str) -> Image:
    """A ``32FC1`` ``sensor_msgs/Image`` of depth in metres, stamped ``stamp`` (nanoseconds).

    Raises :class:`~cyborg.vision.frames.VisionError` unless ``depth`` is a non-empty 2-D
    array.
    """
    metres = np.ascontiguousarray(depth, dtype=np.float32)
    if metres.ndim != 2 or metres.size == 0:
        raise VisionError(f"depth map must be a 2-D array in metres, not {metres.shape}")
    height, width = metres.shape
    return Image(
        header=header(stamp, frame_id), height=height, width=width, encoding="32FC1",
        is_bigendian=0, step=width * 4, data=metres.reshape(-1).view(np.uint8))
