"""Frames from recorded ROS bags: ROS 1 ``.bag`` and ROS 2 bags (``.db3`` or ``.mcap``).

Bags are read with rosbags' ``AnyReader``, so no ROS installation is needed. Images may be
``sensor_msgs/Image`` or ``CompressedImage``; depth maps ``32FC1`` metres or ``16UC1``
millimetres. Topics are given, or found: the depth topic is the image topic with ``depth`` in
its name, the right image the one with ``right``, the left image the remaining one (preferring
``left``, ``rgb`` or ``color``). Streams are paired by exact header stamp; unpaired messages are
counted in :attr:`BagSource.dropped`.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

from typing_extensions import override

from cyborg.vision.frames import Frame, FrameSource, VisionError
from cyborg.vision.image_messages import (
    compressed_to_bgr,
    image_to_bgr,
    image_to_depth,
    stamp_ns,
)
from cyborg.vision.pairing import ExactPairer

IMAGE_TYPES = ("sensor_msgs/msg/Image", "sensor_msgs/msg/CompressedImage")
BAG_SUFFIXES = frozenset({".bag", ".db3", ".mcap"})


def is_bag(path: Path) -> bool:
    """Whether ``path`` is a bag: a ``.bag``, ``.db3`` or ``.mcap`` file, or a bag folder."""
    return (path.suffix.lower() in BAG_SUFFIXES
            or (path.is_dir() and (path / "metadata.yaml").is_file()))


def _bag_path(path: Path) -> Path:
    """A ROS 2 storage file is read through its bag folder (where ``metadata.yaml`` lives)."""
    if path.suffix.lower() in (".db3", ".mcap") and path.is_file():
        if not (path.parent / "metadata.yaml").is_file():
            raise VisionError(f"bag {path}: a ROS 2 bag is a folder with metadata.yaml next to "
                              "its storage files; give the folder")
        return path.parent
    if not path.exists():
        raise VisionError(f"bag {path}: not found")
    if path.suffix.lower() == ".bag" and path.suffix != ".bag":
        raise VisionError(f"bag {path}: ROS 1 bags are read only with the suffix '.bag' in "
                          f"lower case; rename it to {path.with_suffix('.bag').name}")
    return path


class BagSource(FrameSource):
    """Frames of a bag's image topic, with its depth and right-image topics when present."""

    def __init__(self, path: Path, *, image_topic: str | None = None,
                 depth_topic: str | None = None, right_topic: str | None = None) -> None:
        from rosbags.highlevel import AnyReader, AnyReaderError
        from rosbags.typesys import Stores, get_typestore

        super().__init__()
        self.name = str(path)
        try:
            # ROS 2 bags before Iron (rosbag2 storage < 8) carry no message definitions: their
            # sensor_msgs are read with the standard ones
            self.reader = AnyReader([_bag_path(path)],
                                    default_typestore=get_typestore(Stores.ROS2_HUMBLE))
            self.reader.open()
        except (AnyReaderError, OSError, ValueError) as exc:
            raise VisionError(f"bag {path}: cannot be read ({exc})") from exc
        image_topics = {c.topic: c.msgtype for c in self.reader.connections
                        if c.msgtype in IMAGE_TYPES}
        try:
            self.topics = self._choose(path, image_topics, image_topic, depth_topic,
                                       right_topic)
        except VisionError:
            self.reader.close()
            raise
        self.length = sum(c.msgcount for c in self.reader.connections
                          if c.topic == self.topics["image"])
        """The number of image messages: an upper bound when images are paired with depth."""

    def _choose(self, path: Path, found: dict[str, str], image: str | None, depth: str | None,
                right: str | None) -> dict[str, str]:
        for given in (image, depth, right):
            if given is not None and given not in found:
                raise VisionError(f"bag {path}: no image topic {given!r}; image topics: "
                                  f"{', '.join(sorted(found)) or 'none'}")
        if depth is not None and found[depth] != "sensor_msgs/msg/Image":
            raise VisionError(f"bag {path}: depth topic {depth!r} is a {found[depth]}; depth "
                              "must be a sensor_msgs/msg/Image (32FC1 or 16UC1)")
        rest = [topic for topic in sorted(found) if topic not in (image, depth, right)]
        if depth is None:
            depth = next((t for t in rest if "depth" in t.lower()
                          and found[t] == "sensor_msgs/msg/Image"), None)
        if right is None:
            right = next((t for t in rest if "right" in t.lower() and t != depth), None)
        if image is None:
            others = [t for t in rest if t not in (depth, right)]
            preferred = [t for t in others if any(word in t.lower()
                                                  for word in ("left", "rgb", "color"))]
            choices = preferred or others
            if len(choices) != 1:
                raise VisionError(f"bag {path}: cannot tell which topic is the camera image "
                                  f"among {', '.join(others) or 'no image topics'}; give "
                                  "--image-topic")
            image = choices[0]
        topics = {"image": image}
        if depth is not None:
            topics["depth"] = depth
        if right is not None:
            topics["right"] = right
        return topics

    @override
    def frames(self) -> Iterator[Frame]:
        streams = {topic: stream for stream, topic in self.topics.items()}
        pairer = ExactPairer(tuple(self.topics))
        connections = [c for c in self.reader.connections if c.topic in streams]
        index = 0
        for connection, _, raw in self.reader.messages(connections=connections):
            where = f"{self.name} {connection.topic}"
            try:
                message: Any = self.reader.deserialize(raw, connection.msgtype)
            except Exception as exc:  # rosbags raises several types for bad data
                raise VisionError(f"{where}: message cannot be decoded ({exc})") from exc
            stream, stamp = streams[connection.topic], stamp_ns(message.header)
            # the frame is named by its image's frame_id, whichever message completes it
            item = (self._convert(stream, message, where), str(message.header.frame_id))
            complete = pairer.add(stream, stamp, item)
            self.dropped = pairer.dropped
            if complete is None:
                continue
            images = {name: pixels for name, (pixels, _) in complete.items()}
            try:
                frame = Frame(stamp, images["image"], images.get("right"), images.get("depth"),
                              frame_id=complete["image"][1], index=index)
            except VisionError as exc:
                raise VisionError(f"{self.name} at stamp {stamp}: {exc}") from None
            yield frame
            index += 1
        pairer.finish()
        self.dropped = pairer.dropped

    @staticmethod
    def _convert(stream: str, message: Any, where: str) -> Any:
        if stream == "depth":
            return image_to_depth(message, where)
        if hasattr(message, "format"):
            return compressed_to_bgr(message, where)
        return image_to_bgr(message, where)

    @override
    def close(self) -> None:
        if self.reader.stack is not None:
            self.reader.close()
