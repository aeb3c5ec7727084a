"""Simulated time from the ``/clock`` topic, as ROS 2 nodes use it with ``use_sim_time``.

A simulator publishes ``rosgraph_msgs/msg/Clock`` on ``/clock`` after every step. A
:class:`SimClock` follows it, so timers, timeouts and tick rates built on it run at the
simulation's pace — a 13-hour mission in minutes, with unchanged semantics::

    clock = SimClock(node)
    clock.wait_for_time(timeout=10)      # until the first /clock message
    clock.now()                           # seconds of simulated time
    clock.sleep_until(clock.now() + 1.0, stop_event)

It has the shape of :class:`cyborg.bt.Clock` (``now`` and ``sleep_until``), so a behaviour tree
runs on it directly. Before the first message the time is 0, as in ROS. Time never goes back: a
message older than the last one is ignored (a restarted simulator must be followed by a new
clock).
"""

from __future__ import annotations

import threading
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from cyborg.bus.node import Node

CLOCK_TOPIC = "/clock"
CLOCK_TYPE = "rosgraph_msgs/msg/Clock"
_POLL = 0.05  # seconds of wall time between checks of the wake event while sleeping


class SimClock:
    """Simulated time, from ``/clock`` messages received by ``node``."""

    def __init__(self, node: Node, topic: str = CLOCK_TOPIC) -> None:
        self._now = 0.0
        self._received = 0
        self._changed = threading.Condition()
        self._subscription = node.create_subscription(topic, CLOCK_TYPE, self._on_clock)

    def _on_clock(self, message: Any) -> None:
        seconds = message.clock.sec + message.clock.nanosec * 1e-9
        with self._changed:
            if seconds >= self._now:
                self._now = seconds
            self._received += 1
            self._changed.notify_all()

    @property
    def started(self) -> bool:
        """Whether a ``/clock`` message has arrived."""
        return self._received > 0

    def now(self) -> float:
        """Simulated seconds (0 before the first message)."""
        return self._now

    def wait_for_time(self, timeout: float | None = None) -> bool:
        """Wait (wall time) until the first message; False on timeout."""
        with self._changed:
            return self._changed.wait_for(lambda: self._received > 0, timeout)

    def sleep_until(self, deadline: float, wake: threading.Event) -> None:
        """Return when simulated time reaches ``deadline`` or ``wake`` is set.

        While the simulation is paused, this waits (checking ``wake`` every 50 ms of wall time).
        """
        with self._changed:
            while self._now < deadline and not wake.is_set():
                self._changed.wait(_POLL)

    def destroy(self) -> None:
        self._subscription.destroy()
