"""The camera node: plays a frame source on the bus, as a camera driver would.

Publishes, in the node's namespace, ``left/image_raw`` (``bgr8``), and when the source has them
``right/image_raw`` and ``depth/depth_registered`` (``32FC1`` metres), all three stamped alike
with the time of publication so subscribers pair them by exact stamp. The right and depth topics
are advertised only once the source gives its first right image or depth map: a video file
has no depth, and a depth topic with a publisher that never publishes would keep a detector
waiting for depth (:mod:`~cyborg.vision.camera_inputs`) instead of detecting. Files are played at
``rate`` frames per second (looping when asked); a camera at its own pace. On the robot a
ZED driver publishes the same; in simulation this node stands in for it with recorded frames.
The topics are those of :mod:`cyborg.interfaces.detector`.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable

import numpy as np

from cyborg.bus import Node
from cyborg.bus.topics import Publisher
from cyborg.interfaces.contract import Topic
from cyborg.interfaces.detector import CAMERA_FRAME, DEPTH, IMAGE, RIGHT_IMAGE
from cyborg.vision.frames import FrameSource, VisionError
from cyborg.vision.image_messages import bgr_to_image, depth_to_image

log = logging.getLogger(__name__)

IMAGE_TOPIC, RIGHT_TOPIC, DEPTH_TOPIC = IMAGE.name, RIGHT_IMAGE.name, DEPTH.name
"""The topics' names in the camera's namespace."""
DEFAULT_RATE = 15.0
"""Frames per second a file source is played at unless told otherwise."""
DEFAULT_FRAME_ID = CAMERA_FRAME
"""The images' frame unless told otherwise (the contract's ``camera_left``)."""


class CameraNode:
    """Publishes a source's frames from a thread of its own until stopped or exhausted."""

    def __init__(self, node: Node, open_source: Callable[[], FrameSource], *,
                 rate: float = DEFAULT_RATE, loop: bool = True,
                 frame_id: str = DEFAULT_FRAME_ID,
                 now_ns: Callable[[], int] = time.time_ns) -> None:
        self.node, self.open_source = node, open_source
        self.rate, self.loop, self.frame_id, self.now_ns = rate, loop, frame_id, now_ns
        self.image = IMAGE.publisher(node)
        self.right: Publisher | None = None
        """The right images' publisher, created with the first right image (None: none yet)."""
        self.depth: Publisher | None = None
        """The depth maps' publisher, created with the first depth map (None: none yet)."""
        self.published = 0
        self.error: VisionError | None = None
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True,
                                        name=f"cyborg-camera{node.fq_name}")

    def start(self) -> None:
        """Starts publishing from the camera's own thread; an unreadable source ends it.

        The source's :class:`VisionError` is then logged and kept in :attr:`error`.
        """
        self._thread.start()

    def _run(self) -> None:
        period = 1.0 / self.rate if self.rate > 0 else 0.0
        deadline = time.monotonic()
        try:
            while not self._stop.is_set():
                with self.open_source() as source:
                    played = 0
                    for frame in source:
                        if self._stop.is_set():
                            return
                        self._publish(frame.left, frame.right, frame.depth)
                        played += 1
                        deadline += period
                        self._stop.wait(max(0.0, deadline - time.monotonic()))
                if not self.loop or played == 0:
                    return
        except VisionError as exc:
            self.error = exc
            log.error("%s: %s", self.node.fq_name, exc)

    def _publish(self, left: np.ndarray, right: np.ndarray | None,
                 depth: np.ndarray | None) -> None:
        # partners are advertised before the image: a detector that sees the image already
        # sees their publishers, and waits for them
        if right is not None and self.right is None:
            self.right = self._advertise(RIGHT_IMAGE)
        if depth is not None and self.depth is None:
            self.depth = self._advertise(DEPTH)
        stamp = self.now_ns()
        if right is not None and self.right is not None:
            self.right.publish(bgr_to_image(right, stamp, self.frame_id))
        if depth is not None and self.depth is not None:
            self.depth.publish(depth_to_image(depth, stamp, self.frame_id))
        self.image.publish(bgr_to_image(left, stamp, self.frame_id))
        self.published += 1

    def _advertise(self, topic: Topic) -> Publisher:
        return topic.publisher(self.node)

    def stop(self) -> None:
        """Stops publishing, waiting up to 2 s for the camera's thread to end."""
        self._stop.set()
        if self._thread.is_alive() and threading.current_thread() is not self._thread:
            self._thread.join(2.0)
