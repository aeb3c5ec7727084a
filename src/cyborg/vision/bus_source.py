"""Frames from camera topics on the bus, for offline tools (``cyborg detect bus:TOPIC``).

Subscribes to the image topic (and depth and right-image topics when given), pairs them by
exact stamp, and hands out the newest complete frame; frames that arrive while the consumer is
busy are dropped and counted, as a live camera's would be.
"""

from __future__ import annotations

import queue
from collections.abc import Iterator
from typing import Any

from typing_extensions import override

from cyborg.bus import Node
from cyborg.interfaces.detector import CAMERA_STREAMS
from cyborg.vision.camera_topics import CameraTopics
from cyborg.vision.frames import Frame, FrameSource, VisionError
from cyborg.vision.image_messages import stamp_ns
from cyborg.vision.pairing import ExactPairer

_END = object()


class BusSource(FrameSource):
    """Live frames from the bus until :meth:`close` (or ``idle_timeout`` without a frame)."""

    def __init__(self, node: Node, topics: CameraTopics, *, idle_timeout: float | None = None
                 ) -> None:
        super().__init__()
        self.node, self.topics, self.idle_timeout = node, topics, idle_timeout
        self.name = f"bus {topics.image}"
        streams = topics.streams()
        self.pairer = ExactPairer(streams, max_pending=10)
        self._queue: queue.Queue[Any] = queue.Queue(maxsize=2)
        self._subscriptions = [
            CAMERA_STREAMS[stream].remapped(getattr(topics, stream)).subscription(
                node, self._receiver(stream))
            for stream in streams]
        self._index = 0

    def _receiver(self, stream: str) -> Any:
        def receive(message: Any) -> None:
            complete = self.pairer.add(stream, stamp_ns(message.header), message)
            if complete is None:
                return
            if self._queue.full():
                try:
                    self._queue.get_nowait()
                    self.dropped += 1
                except queue.Empty:
                    pass
            self._queue.put_nowait(complete)
        return receive

    @override
    def frames(self) -> Iterator[Frame]:
        while True:
            try:
                item = self._queue.get(timeout=self.idle_timeout)
            except queue.Empty:
                return
            if item is _END:
                return
            try:
                frame = self.topics.frame(item, self._index)
            except VisionError as exc:
                raise VisionError(f"{self.name}: {exc}") from None
            self._index += 1
            yield frame

    @property
    def total_dropped(self) -> int:
        """Frames dropped in all: while the consumer was busy, and unpaired by the pairer."""
        return self.dropped + self.pairer.dropped

    def close(self) -> None:
        """Ends :meth:`frames` after what is queued (one frame may be dropped); any thread.

        The subscriptions stay until the node is destroyed.
        """
        try:
            self._queue.put_nowait(_END)
        except queue.Full:
            self._queue.get_nowait()
            self._queue.put_nowait(_END)
