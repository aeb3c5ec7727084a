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

:class:`PaceWindow` is the same idea for simulated time: how many simulated seconds pass per
wall-clock second, over a window; :class:`FallingBehind` says once when that stays below half
of the pace asked (``cyborg up``'s live line shows both).
"""

from __future__ import annotations

import itertools
import os
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


PACE_WINDOW = 5.0
"""Wall-clock seconds over which the pace of simulated time is measured."""
SLOW_PATIENCE = 10.0
"""Wall-clock seconds the pace must stay below half the asked one before it is said."""


class PaceWindow:
    """The pace simulated time actually runs at: simulated seconds per wall-clock second.

    Fed the simulated time of each tick (:meth:`add`); :meth:`pace` is the simulated time
    passed over the last ``window`` wall-clock seconds, divided by them. ``wall`` is the wall
    clock (injected in tests).
    """

    def __init__(self, wall: Callable[[], float] = time.monotonic, *,
                 window: float = PACE_WINDOW) -> None:
        self._wall = wall
        self._window = window
        self._samples: deque[tuple[float, float]] = deque()

    def add(self, simulated: float) -> None:
        """Notes that simulated time is ``simulated`` now."""
        now = self._wall()
        samples = self._samples
        if samples and simulated < samples[-1][1]:  # simulated time went back: start over
            samples.clear()
        samples.append((now, simulated))
        while len(samples) > 2 and samples[1][0] <= now - self._window:
            samples.popleft()

    def pace(self) -> float | None:
        """Simulated seconds per wall second over the window; None before a second has passed."""
        if len(self._samples) < 2:
            return None
        (wall0, sim0), (wall1, sim1) = self._samples[0], self._samples[-1]
        if wall1 - wall0 < min(1.0, self._window):
            return None
        return (sim1 - sim0) / (wall1 - wall0)


class FallingBehind:
    """Says once when simulated time runs at less than half the ``asked`` pace for a while.

    :meth:`check` is given the pace reached (:class:`PaceWindow`) and returns the warning the
    first time the pace has stayed below half of ``asked`` for ``patience`` wall-clock seconds:
    what was asked and reached, why (the CPU is busy: the load average and the CPUs, from
    ``load``), and what to do (a lower ``--speed``, or ``--speed 0``). An ``asked`` of 0 (as
    fast as possible) is never behind.
    """

    def __init__(self, asked: float, wall: Callable[[], float] = time.monotonic, *,
                 patience: float = SLOW_PATIENCE,
                 load: Callable[[], tuple[float, int | None]] | None = None) -> None:
        self.asked = asked
        self._wall = wall
        self._patience = patience
        self._load = load or _load_and_cpus
        self._since: float | None = None
        self.warned = False

    def check(self, pace: float | None) -> str | None:
        """The warning, the once it is due; None otherwise."""
        if self.warned or self.asked <= 0 or pace is None or pace >= self.asked / 2:
            self._since = None
            return None
        now = self._wall()
        if self._since is None:
            self._since = now
        if now - self._since < self._patience:
            return None
        self.warned = True
        load, cpus = self._load()
        on = f" on {cpus} CPU{'s' if cpus != 1 else ''}" if cpus else ""
        busy = cpus is None or not load < cpus  # unknown, or every CPU has work waiting
        why = (f"the CPU is busy (load average {load:.1f}{on})" if busy else
               f"the simulation itself is the limit, not the CPU (load average {load:.1f}{on}: "
               "one process steps it, on one CPU)")
        slower = max(1, int(pace))
        return (f"the simulation runs at {pace:.1f}x real time, below half the {self.asked:g}x "
                f"asked (--speed), for {self._patience:g} s: {why}, so the tree's timing and "
                f"the battery's stretch in wall time; ask for what it reaches, --speed {slower}, "
                "or --speed 0 (as fast as the CPU allows, timing kept on simulated time)")


def _load_and_cpus() -> tuple[float, int | None]:
    """The 1-minute load average and the number of CPUs."""
    try:
        load = os.getloadavg()[0]
    except OSError:  # not on this system
        load = float("nan")
    return load, os.cpu_count()
