"""Pairing streams by exact timestamp: an image with its depth map (and right image).

A camera driver stamps the image and the depth map of one exposure with the same time, so they
are paired by *exact* stamp, as the 2018 node did. Whatever cannot be paired — a depth map whose
image never came, an image that was overtaken by a newer complete pair, or anything beyond
``max_pending`` waiting items — is dropped and counted in :attr:`ExactPairer.dropped`.
"""

from __future__ import annotations

from collections import OrderedDict
from typing import Any


class ExactPairer:
    """Collects items of named streams; returns a complete set once every stream has a stamp.

    ::

        pairer = ExactPairer(("image", "depth"))
        pairer.add("image", stamp, left)           # None: still waiting
        pairer.add("depth", stamp, depth)          # {"image": left, "depth": depth}
    """

    def __init__(self, streams: tuple[str, ...], max_pending: int = 30) -> None:
        if not streams or len(set(streams)) != len(streams):
            # a stream named twice could never complete a set: every item would be dropped
            raise ValueError(f"streams must be distinct names, at least one, not {streams!r}")
        self.streams = streams
        self.max_pending = max_pending
        self.pending: OrderedDict[int, dict[str, Any]] = OrderedDict()
        self.dropped = 0
        """Items dropped without a partner."""

    def add(self, stream: str, stamp: int, item: Any) -> dict[str, Any] | None:
        """Add one item; the complete set of ``stamp`` when this completed it."""
        if stream not in self.streams:
            raise KeyError(f"unknown stream {stream!r}; streams: {', '.join(self.streams)}")
        if len(self.streams) == 1:
            return {stream: item}
        waiting = self.pending.setdefault(stamp, {})
        if stream in waiting:
            self.dropped += 1  # the same stamp twice on one stream: keep the newer
        waiting[stream] = item
        if len(waiting) < len(self.streams):
            while len(self.pending) > self.max_pending:
                _, oldest = self.pending.popitem(last=False)
                self.dropped += len(oldest)
            return None
        complete = self.pending.pop(stamp)
        for older in [key for key in self.pending if key < stamp]:
            self.dropped += len(self.pending.pop(older))
        return complete

    def finish(self) -> None:
        """The streams ended: whatever still waits is dropped."""
        self.dropped += sum(len(items) for items in self.pending.values())
        self.pending.clear()
