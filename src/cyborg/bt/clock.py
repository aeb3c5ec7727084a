"""Clocks: where a tree's time comes from.

Every time-dependent part of the engine (Wait, Timeout, the runner's tick rate) reads time from
a :class:`Clock` that is passed in, never from the system directly. On the robot that is
:class:`MonotonicClock`; in a simulation it is the simulator's clock, so a 13-hour mission can
run in minutes with unchanged semantics; in tests it is :class:`ManualClock`.
"""

from __future__ import annotations

import threading
import time
from typing import Protocol


class Clock(Protocol):
    """A source of time in seconds."""

    def now(self) -> float:
        """Current time in seconds; only differences matter."""
        ...

    def sleep_until(self, deadline: float, wake: threading.Event) -> None:
        """Returns when :meth:`now` reaches ``deadline``, or earlier when ``wake`` is set."""
        ...


class MonotonicClock:
    """Wall-clock time that never jumps backwards (``time.monotonic``)."""

    def now(self) -> float:
        """Seconds of ``time.monotonic``, from an arbitrary start."""
        return time.monotonic()

    def sleep_until(self, deadline: float, wake: threading.Event) -> None:
        """Blocks the calling thread until ``deadline`` or until ``wake`` is set."""
        delay = deadline - time.monotonic()
        if delay > 0:
            wake.wait(delay)


class ManualClock:
    """A clock that moves only when told to; sleeping jumps straight to the deadline.

    A runner on this clock ticks as fast as the CPU allows while its nodes see time advance at
    the configured rate: the way to fast-forward a scenario.
    """

    def __init__(self, start: float = 0.0) -> None:
        self._now = start
        self._lock = threading.Lock()

    def now(self) -> float:
        """The seconds the clock was started at or last moved to."""
        return self._now

    def advance(self, seconds: float) -> None:
        """Moves time forward by ``seconds``; :class:`ValueError` if they are negative."""
        if seconds < 0:
            raise ValueError(f"a clock cannot go back ({seconds} s)")
        with self._lock:
            self._now += seconds

    def set(self, now: float) -> None:
        """Moves time forward to ``now``; :class:`ValueError` if that lies in the past."""
        with self._lock:
            if now < self._now:
                raise ValueError(f"a clock cannot go back from {self._now} to {now}")
            self._now = now

    def sleep_until(self, deadline: float, wake: threading.Event) -> None:
        """Jumps to ``deadline`` at once if it lies ahead; never blocks, ignores ``wake``."""
        with self._lock:
            if deadline > self._now:
                self._now = deadline
