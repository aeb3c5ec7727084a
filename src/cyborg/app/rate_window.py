r"""The arithmetic of ``cyborg topic hz``: a window of arrival times and the rate it shows.

Pure and clock-injected, so it is tested without a bus. The command calls :meth:`RateWindow.
arrived` from the subscription callback and :meth:`RateWindow.report` once per report period,
printing :func:`hz_line` of the result, as ``ros2 topic hz`` does::

    average rate: 10.000
    \tmin: 0.100s max: 0.100s window: 11

A report with no message since the one before is ``no new messages``. So that a publisher that
stops does not keep its old rate, and one that resumes is measured afresh rather than mixed with
its past, a silence ends the window: at a report with nothing new, the arrival times are dropped
once the silence is longer than ``stale_gaps`` of the window's mean gap. A topic slower than the
report period (a silent report between two messages) thus keeps its window; a lone message,
whose gap is unknown, is dropped after ``lone_limit`` seconds.
"""

from __future__ import annotations

import itertools
import threading
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass

WINDOW_SIZE = 1000
"""The arrival times kept, the newest."""
STALE_GAPS = 3.0
"""A silence this many mean gaps long ends the window."""
LONE_LIMIT = 10.0
"""Seconds a lone arrival waits for a second one."""


@dataclass(frozen=True)
class Rate:
    """The rate over the window: ``count`` arrivals, ``count - 1`` gaps (in seconds)."""

    rate: float
    min_gap: float
    max_gap: float
    count: int


class RateWindow:
    """The latest arrival times of a topic's messages; thread-safe."""

    def __init__(self, clock: Callable[[], float] = time.monotonic, *, size: int = WINDOW_SIZE,
                 stale_gaps: float = STALE_GAPS, lone_limit: float = LONE_LIMIT) -> None:
        if size < 2:
            raise ValueError(f"a rate needs a window of at least 2 arrivals, not {size}")
        self._clock = clock
        self._stamps: deque[float] = deque(maxlen=size)
        self._stale_gaps = stale_gaps
        self._lone_limit = lone_limit
        self._new = False  # an arrival since the last report
        self._lock = threading.Lock()

    def arrived(self) -> None:
        """Notes a message arriving now."""
        stamp = self._clock()
        with self._lock:
            self._stamps.append(stamp)
            self._new = True

    def report(self) -> Rate | None:
        """The rate over the window, or None when there is none to show.

        None when no message came since the last report (the window is dropped if the silence
        is long enough), or only one.
        """
        now = self._clock()
        with self._lock:
            new, self._new = self._new, False
            if not new:
                if self._stamps and now - self._stamps[-1] > self._stale_after():
                    self._stamps.clear()
                return None
            if len(self._stamps) < 2:
                return None
            gaps = [b - a for a, b in itertools.pairwise(self._stamps)]
            span = self._stamps[-1] - self._stamps[0]
            count = len(self._stamps)
        if span <= 0:  # arrivals within one tick of the clock
            return None
        return Rate(len(gaps) / span, min(gaps), max(gaps), count)

    def _stale_after(self) -> float:
        """How long a silence ends the window (with the lock held)."""
        if len(self._stamps) < 2:
            return self._lone_limit
        mean_gap = (self._stamps[-1] - self._stamps[0]) / (len(self._stamps) - 1)
        return self._stale_gaps * mean_gap


def hz_line(rate: Rate | None) -> str:
    """What ``topic hz`` prints for one report (two lines for a rate)."""
    if rate is None:
        return "no new messages"
    return (f"average rate: {rate.rate:.3f}\n\tmin: {rate.min_gap:.3f}s max: "
            f"{rate.max_gap:.3f}s window: {rate.count}")
