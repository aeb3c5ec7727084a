"""Where a camera's streams are on the bus, and how one stamp's messages become a frame."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from cyborg.vision.frames import Frame
from cyborg.vision.image_messages import image_to_bgr, image_to_depth, stamp_ns


@dataclass(frozen=True)
class CameraTopics:
    """The colour image's topic, and optionally the depth map's and the right image's."""

    image: str
    depth: str = ""
    right: str = ""

    def streams(self) -> tuple[str, ...]:
        """The streams to pair: ``image``, then ``depth`` and ``right`` when given."""
        return tuple(stream for stream in ("image", "depth", "right") if getattr(self, stream))

    def frame(self, messages: dict[str, Any], index: int = 0) -> Frame:
        """The frame of one stamp's messages (``VisionError`` names the topic at fault)."""
        image = messages["image"]
        return Frame(stamp_ns(image.header), image_to_bgr(image, self.image),
                     image_to_bgr(messages["right"], self.right) if "right" in messages
                     else None,
                     image_to_depth(messages["depth"], self.depth) if "depth" in messages
                     else None,
                     frame_id=str(image.header.frame_id), index=index)
