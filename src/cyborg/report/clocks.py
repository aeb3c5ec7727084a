"""The two clocks of a recording: the wall clock it was recorded on, and simulated time.

Every message in a recording has a *log time*: when the recorder received it, on the wall
clock. A run under a simulator also records ``/clock``, the simulated time the simulator, the
tree and the navigator go by; at ``--speed 30`` a wall minute holds half a simulated hour. A
report must say which clock a figure is on: the recording's duration and a goal's start are
wall time, a node's running time is the tree's clock (simulated time under a simulator).
:class:`RunClock` maps a log time onto simulated time, from the ``/clock`` messages (read one
per wall second, :data:`CLOCK_SAMPLE_NS`; interpolated between them), so a report can give a
span on both clocks::

    run = run_clock(recording.stamped("/clock"))
    if run is not None and run.differs:
        run.simulated_span(attempt.start, attempt.end)   # seconds of simulated time

A recording without ``/clock`` ran on the wall clock alone (or its simulated time was not
recorded): :func:`run_clock` gives None and every figure is wall time.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cyborg.report.recording import Stamped

CLOCK_SAMPLE_NS = 1_000_000_000
"""The report decodes one ``/clock`` message per this many nanoseconds of log time (a
simulator publishes one per physics step: thousands a wall second at 30x)."""
SAME_PACE = 0.02
"""Simulated time that runs within this share of the wall clock's pace is "the same": a figure
is then given once."""


@dataclass(frozen=True)
class RunClock:
    """Simulated time against log time, from the recorded ``/clock`` (see the module)."""

    log_times: np.ndarray
    """Log times (ns) of the ``/clock`` messages read, rising."""
    simulated: np.ndarray
    """The simulated time (ns) each of them carried."""

    def simulated_at(self, log_time: int) -> float:
        """Simulated seconds at ``log_time`` (ns), counted from the first ``/clock`` read."""
        value = np.interp(float(log_time), self.log_times, self.simulated)
        return float(value - self.simulated[0]) / 1e9

    def simulated_span(self, start: int, end: int) -> float:
        """Simulated seconds between two log times (ns)."""
        return self.simulated_at(end) - self.simulated_at(start)

    @property
    def duration(self) -> float:
        """Simulated seconds from the first ``/clock`` read to the last."""
        return float(self.simulated[-1] - self.simulated[0]) / 1e9

    @property
    def pace(self) -> float:
        """Simulated seconds per wall second over the recording (1.0 without a span)."""
        wall = float(self.log_times[-1] - self.log_times[0]) / 1e9
        return self.duration / wall if wall > 0 else 1.0

    @property
    def differs(self) -> bool:
        """Whether simulated time ran at another pace than the wall clock (give both)."""
        return abs(self.pace - 1.0) > SAME_PACE


def run_clock(messages: list[Stamped]) -> RunClock | None:
    """The recording's simulated time from its ``/clock`` messages; None with fewer than two.

    A ``/clock`` that goes back (a restarted simulator) keeps its last stretch that only rises.
    """
    if len(messages) < 2:
        return None
    log_times = np.array([item.log_time for item in messages], np.int64)
    simulated = np.array([int(item.message.clock.sec) * 1_000_000_000
                          + int(item.message.clock.nanosec) for item in messages], np.int64)
    backs = np.flatnonzero(np.diff(simulated) < 0)
    if len(backs):
        first = int(backs[-1]) + 1
        log_times, simulated = log_times[first:], simulated[first:]
    if len(log_times) < 2:
        return None
    return RunClock(log_times, simulated)
