"""ROS messages and bags for the tests of camera sources and image messages.

Image and compressed image messages built from numpy arrays, and bags written with rosbags' own
writers (ROS 1, ROS 2 sqlite3 and mcap); ``camera_bag`` is a colour and depth camera whose
streams pair at two stamps of four.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import cv2
import numpy as np
from rosbags.rosbag1 import Writer as Writer1
from rosbags.rosbag2 import StoragePlugin
from rosbags.rosbag2 import Writer as Writer2
from rosbags.typesys import Stores, get_typestore
from rosbags.typesys.store import Typestore

from cyborg.vision import depth_in_metres
from tests.vision.source_fixtures import T0, texture

JAZZY = get_typestore(Stores.ROS2_JAZZY)
NOETIC = get_typestore(Stores.ROS1_NOETIC)
IMAGE, COMPRESSED = "sensor_msgs/msg/Image", "sensor_msgs/msg/CompressedImage"
STRING = "std_msgs/msg/String"


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
