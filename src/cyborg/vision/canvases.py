"""Reusable image buffers for the annotated image, handed out again only once they are free.

A fresh 6 MB array per frame is not free: the kernel maps new pages for it and zeroes them
(a few 2 MB pages per frame, about 0.1 ms each here) before the copy of the frame overwrites
every byte. :class:`Canvases` keeps a few buffers instead and hands one out again once nothing
else refers to it.

"Nothing else" is CPython's reference count: every numpy view of a buffer, every message that
carries it and every ``memoryview`` of it holds a reference to the buffer itself, so while a
subscriber keeps the annotated image of an earlier frame, that buffer stays out of use and
another one is taken.
"""

from __future__ import annotations

import sys

import numpy as np

_UNUSED = 3
"""References to a buffer nobody else holds: the pool's list, the loop variable and
``getrefcount``'s own argument."""


class Canvases:
    """Up to ``keep`` uint8 buffers; :meth:`take` returns one that nothing else refers to."""

    def __init__(self, keep: int = 3) -> None:
        self.keep = keep
        self._buffers: list[np.ndarray] = []

    def take(self, shape: tuple[int, ...]) -> np.ndarray:
        """A writable uint8 array of ``shape`` (contents undefined) that no one else holds."""
        for buffer in self._buffers:
            if buffer.shape == shape and sys.getrefcount(buffer) <= _UNUSED:
                return buffer
        fresh = np.empty(shape, dtype=np.uint8)
        self._buffers = [b for b in self._buffers if b.shape == shape][-(self.keep - 1):] \
            if self.keep > 1 else []
        if self.keep:
            self._buffers.append(fresh)
        return fresh
