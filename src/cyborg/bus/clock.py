"""Simulated time from the ``/clock`` topic, as ROS 2 nodes use it with ``use_sim_time``.

A simulator publishes ``rosgraph_msgs/msg/Clock`` on ``/clock`` after every step. A
:class:`SimClock` follows it, so timers, timeouts and tick rates built on it run at the
simulation's pace — a 13-hour mission in minutes, with unchanged semantics::

    clock = SimClock(node)
    clock.wait_for_time(timeout=10)      # until the first /clock message
    clock.now()                           # seconds of simulated time
    clock.sleep_until(clock.now() + 1.0, stop_event)

It has the shape of :class:`cyborg.bt.Clock` (``now`` and ``sleep_until``), so a behaviour tree
runs on it directly. Before the first message the time is 0, as in ROS.

**Whom it follows.** Anyone on the network can publish on ``/clock``, so the clock follows one
publisher at a time, the *current* one (told apart by the GID in each sample's attachment):

* the first message makes its publisher the current one;
* the current publisher's messages are always followed, as ROS 2 follows ``/clock``: when time
  goes back every sleeper wakes (ROS 2 resets its timers; a tree runner restarts its schedule),
  and a jump back or forward by more than ``jump_limit`` seconds is logged;
* other publishers are ignored (counted in :attr:`SimClock.ignored`, logged at most every 10 s)
  while the current one is *present*: in the graph, or, for a publisher that never was, heard
  within ``stall_timeout`` wall seconds. A publisher that is in the graph takes over from one
  that is not;
* once the current publisher is gone (a simulator that stopped or restarted leaves the graph),
  the next publisher takes over at once, whatever its time — except a jump forward by more than
  ``jump_limit`` from a publisher that is not in the graph, which is refused.

So a forged message far in the future is ignored while the simulator runs, and a restarted
simulator (time from 0, a new publisher) is followed the moment it publishes. A GID is not a
signature: a sender that copies the current publisher's GID is followed like it
(``docs/security.md``).

**Stalls.** A sleeper that sees simulated time stand still for ``stall_timeout`` wall seconds
logs it once (with the publisher and the count of ignored messages), and again when time moves.
"""

from __future__ import annotations

import logging
import threading
import time
from typing import TYPE_CHECKING, Any

from cyborg.bus.wire import Attachment, EntityKind, gid

if TYPE_CHECKING:
    from cyborg.bus.node import Node

log = logging.getLogger("cyborg.bus")

CLOCK_TOPIC = "/clock"
CLOCK_TYPE = "rosgraph_msgs/msg/Clock"
JUMP_LIMIT = 10.0
"""Seconds of simulated time one message may move the clock, either way, without being a jump
(logged; a forward one is refused from a publisher that is neither current nor in the graph)."""
STALL_TIMEOUT = 5.0
"""Wall seconds without simulated time advancing after which a sleeper reports a stall."""
_POLL = 0.05  # seconds of wall time between checks of the wake event while sleeping
_REPEAT = 10.0  # wall seconds between two reports of ignored messages

Report = tuple[int, str, tuple[Any, ...]]  # a log record to emit once the lock is released


class SimClock:
    """Simulated time, from ``/clock`` messages received by ``node`` (see the module doc).

    ``topic`` is the clock topic; ``jump_limit`` and ``stall_timeout`` are seconds, as
    :data:`JUMP_LIMIT` and :data:`STALL_TIMEOUT` (ValueError unless positive).
    """

    def __init__(self, node: Node, topic: str = CLOCK_TOPIC, *, jump_limit: float = JUMP_LIMIT,
                 stall_timeout: float = STALL_TIMEOUT) -> None:
        if not (jump_limit > 0 and stall_timeout > 0):
            raise ValueError(f"jump_limit ({jump_limit}) and stall_timeout ({stall_timeout}) "
                             "must be positive seconds")
        self.jump_limit, self.stall_timeout = float(jump_limit), float(stall_timeout)
        self.ignored = 0
        """Messages not followed: from another publisher, or a refused jump."""
        self.jumps = 0
        """Jumps beyond ``jump_limit`` that were followed."""
        self._graph = node.context.graph
        self._now = 0.0
        self._received = 0
        self._epoch = 0  # backward steps so far: a sleeper of an earlier epoch wakes
        self._source: bytes | None = None  # GID of the current publisher (b"": no attachment)
        self._source_name = "none yet"  # how the log names it (kept after it leaves the graph)
        self._listed = False  # whether the current publisher has been seen in the graph
        self._heard = 0.0  # wall time (monotonic) of its last message
        self._moved = time.monotonic()  # wall time simulated time last changed
        self._stalled = False
        self._said_ignored = -_REPEAT
        self._gids: tuple[int, frozenset[bytes]] = (-1, frozenset())
        self._changed = threading.Condition()
        self.topic = topic  # set before subscribing: a latched message may arrive at once
        self._subscription = node.create_subscription(topic, CLOCK_TYPE, self._on_clock,
                                                      with_info=True)
        self.topic = self._subscription.topic

    # ------------------------------------------------------------------ arrivals
    def _on_clock(self, message: Any, info: Attachment | None) -> None:
        seconds = float(message.clock.sec) + float(message.clock.nanosec) * 1e-9
        source = info.gid if info is not None else b""
        with self._changed:
            report = self._follow(source, seconds, time.monotonic())
            if report is not None:  # said before a woken sleeper (who may log too) goes on
                log.log(report[0], report[1], *report[2])

    def _follow(self, source: bytes, seconds: float, wall: float) -> Report | None:
        """Decide about one message (under the lock); what to log, if anything."""
        previous, current = self._now, self._source
        took_over = self._received > 0 and source != current
        if took_over:
            if self._present(source, wall):
                return self._ignore(source, seconds, wall, "following %s")
            if seconds - previous > self.jump_limit and source not in self._publishers():
                return self._ignore(source, seconds, wall, "a jump forward from a publisher "
                                    "outside the graph, after %s left")
            self._listed = False
        previous_name = self._source_name
        if source != current:
            self._source_name = self._describe(source)
        self._source, self._heard = source, wall
        if not self._listed and source in self._publishers():
            self._listed, self._source_name = True, self._describe(source)
        self._received += 1
        self._changed.notify_all()
        step, resumed = seconds - previous, False
        if step:
            self._now, self._moved = seconds, wall
            if step < 0:
                self._epoch += 1
            resumed, self._stalled = self._stalled, False
        if self._received > 1 and abs(step) > self.jump_limit:
            self.jumps += 1
            return (logging.WARNING, "%s jumped %s from %.3f s to %.3f s (%s%s)%s",
                    (self.topic, "back" if step < 0 else "forward", previous, seconds,
                     self._source_name,
                     f", after {previous_name} left" if took_over else "",
                     "; timers and waits restart" if step < 0 else ""))
        if took_over:
            return (logging.INFO, "%s now comes from %s (%s left)",
                    (self.topic, self._source_name, previous_name))
        if resumed:
            return (logging.INFO, "simulated time moves again (%.3f s)", (seconds,))
        return None

    def _present(self, candidate: bytes, wall: float) -> bool:
        """Whether the current publisher still holds the clock against ``candidate``."""
        publishers = self._publishers()
        if self._source in publishers:
            if not self._listed:
                self._listed, self._source_name = True, self._describe(self._source)
            return True
        if self._listed or candidate in publishers:  # it left, or a listed one takes over
            return False
        return wall - self._heard < self.stall_timeout

    def _ignore(self, source: bytes, seconds: float, wall: float, why: str) -> Report | None:
        self.ignored += 1
        if wall - self._said_ignored < _REPEAT:
            return None
        self._said_ignored = wall
        return (logging.WARNING, "ignoring %s at %.3f s from %s: " + why +
                " (%d ignored so far, said at most every %.0f s)",
                (self.topic, seconds, self._describe(source), self._source_name,
                 self.ignored, _REPEAT))

    def _publishers(self) -> frozenset[bytes]:
        """GIDs of the publishers on the clock's topic in the graph (recomputed on change)."""
        version = self._graph.version
        if version != self._gids[0]:
            endpoints = self._graph.endpoints(self.topic, EntityKind.PUBLISHER)
            self._gids = (version, frozenset(gid(e.key) for e in endpoints))
        return self._gids[1]

    def _describe(self, source: bytes) -> str:
        """A publisher for the log: its node when the graph knows it, else its GID."""
        if not source:
            return "a sender without an rmw_zenoh attachment"
        for endpoint in self._graph.endpoints(self.topic, EntityKind.PUBLISHER):
            if gid(endpoint.key) == source:
                return f"publisher {endpoint.node_name} [{source.hex()[:8]}]"
        return f"unknown publisher [{source.hex()[:8]}]"

    # ------------------------------------------------------------------ reading and waiting
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
        """Return when simulated time reaches ``deadline``, goes back, or ``wake`` is set.

        While the simulation is paused this waits, checking ``wake`` every 50 ms of wall time,
        and reports once when time has stood still for ``stall_timeout`` wall seconds.
        """
        with self._changed:
            epoch = self._epoch
            while self._now < deadline and self._epoch == epoch and not wake.is_set():
                self._changed.wait(_POLL)
                if not self._stalled and self._received:
                    self._check_stall()

    def _check_stall(self) -> None:
        idle = time.monotonic() - self._moved
        if idle < self.stall_timeout:
            return
        self._stalled = True
        log.warning("simulated time has not advanced for %.1f s of wall time: %s stands at "
                    "%.3f s, last message %.1f s ago from %s; %d from other publishers ignored",
                    idle, self.topic, self._now, time.monotonic() - self._heard,
                    self._source_name, self.ignored)

    def destroy(self) -> None:
        """Stop following ``/clock``: the time stays where it is."""
        self._subscription.destroy()
