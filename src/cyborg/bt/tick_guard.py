"""Interrupting a tick that does not end: the way a stop always reaches a busy tree.

A node's code runs in the ticking thread, and Python cannot stop a thread from outside. What it
can do is *raise an exception in it*: :class:`TickGuard` knows when its loop's thread is inside
a tick (or inside the services run between ticks), since when, and in which node, and
:meth:`TickGuard.interrupt` raises :class:`TickInterrupted` there. The exception arrives at the
thread's next Python instruction, so a node looping in Python (a ``while`` that never ends) is
stopped at once; a node blocked in a call that waits outside Python (a lock, a socket, a very
long arithmetic operation) would be stopped only when that call returns. A halt therefore
interrupts only a tick that *computes* (:meth:`TickGuard.computing`: its thread used the CPU
while the halt waited); one that waits on the robot ends by itself, and cutting it off when the
robot's answer arrives would lose what the node was told. A tick past its limit is interrupted
whatever it does.

:class:`~cyborg.bt.status.TickInterrupted` derives from :class:`BaseException`, so a node's
own ``except Exception`` does not swallow it; its ``finally`` blocks and ``with`` statements
still run, and every node it passes is left RUNNING, so the halt that follows reaches it. The
loop (:class:`~cyborg.bt.tick_loop.TickLoop`) catches it, halts the tree and says where it was.
At most one interruption is sent per tick, and one not yet delivered when the tick ends is
withdrawn, so it never lands outside the tick it was meant for.
"""

from __future__ import annotations

import ctypes
import sys
import threading
import time
from time import perf_counter
from types import FrameType

from cyborg.bt.node import Node
from cyborg.bt.status import RUNNING, TickInterrupted

__all__ = ["COMPUTING_SHARE", "TickGuard", "TickInterrupted", "mark_cut_off"]

COMPUTING_SHARE = 0.1
"""The share of a wait's wall time a tick must use the CPU to count as computing (a tick
blocked on the robot uses none)."""


def _raise_in(thread_id: int, exception: type[BaseException] | None) -> None:
    """Raises ``exception`` in the thread ``thread_id`` at its next instruction (None: withdraw)."""
    ctypes.pythonapi.PyThreadState_SetAsyncExc(
        ctypes.c_ulong(thread_id), None if exception is None else ctypes.py_object(exception))


class TickGuard:
    """Watches one loop's thread while it ticks; interrupts it on request (see the module)."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._thread_id: int | None = None
        self._since = 0.0
        self._reason: str | None = None

    def enter(self) -> None:
        """The calling thread starts a tick (or a services run) that may be interrupted."""
        with self._lock:
            self._thread_id = threading.get_ident()
            self._since = perf_counter()
            self._reason = None

    def leave(self) -> str | None:
        """The tick has ended: withdraws an interruption not yet delivered; returns its reason.

        Safe to call again after an interruption arrived inside it (the loop does so).
        """
        with self._lock:
            reason = self._reason
            if reason is not None and self._thread_id is not None:
                _raise_in(self._thread_id, None)
            self._thread_id = None
            return reason

    def busy_for(self) -> float | None:
        """Seconds the current tick has been running; None between ticks."""
        with self._lock:
            return None if self._thread_id is None else perf_counter() - self._since

    def interrupt(self, reason: str) -> bool:
        """Raises :class:`TickInterrupted` in the tick in progress; False when there is none.

        A tick is interrupted once: a second request while the first is on its way does
        nothing and returns False.
        """
        with self._lock:
            if self._thread_id is None or self._reason is not None:
                return False
            self._reason = reason
            _raise_in(self._thread_id, _reason_type(reason))
            return True

    def cpu_time(self) -> float | None:
        """CPU seconds the ticking thread has used so far; None between ticks."""
        with self._lock:
            thread_id = self._thread_id
        if thread_id is None:
            return None
        try:
            return time.clock_gettime(time.pthread_getcpuclockid(thread_id))
        except (OSError, AttributeError):  # the thread has just ended, or no such clock
            return None

    def computing(self, cpu_before: float | None, wall_seconds: float) -> bool:
        """Whether the tick computes rather than waits.

        True when it used the CPU for :data:`COMPUTING_SHARE` or more of ``wall_seconds``
        since :meth:`cpu_time` said ``cpu_before``.
        """
        cpu_now = self.cpu_time()
        if cpu_before is None or cpu_now is None:
            return False
        return cpu_now - cpu_before >= COMPUTING_SHARE * wall_seconds

    def reason(self) -> str | None:
        """Why the current tick was interrupted, if it was."""
        with self._lock:
            return self._reason

    def where(self) -> str:
        """The node the ticking thread is in now, as the node's log lines name it; empty if none."""
        with self._lock:
            thread_id = self._thread_id
        if thread_id is None:
            return ""
        frame: FrameType | None = sys._current_frames().get(thread_id)
        while frame is not None:
            node = frame.f_locals.get("self")
            if isinstance(node, Node):
                return f"node {node.uid} ({node.label}, {node.name})"
            frame = frame.f_back
        return ""


def mark_cut_off(exc: TickInterrupted) -> list[Node]:
    """Leaves RUNNING every node ``exc`` passed on its way out of the tick; returns them.

    A node cut off mid-tick may have started something (a goal sent) before it could say
    RUNNING: so marked, the halt that follows reaches it and its ``on_halt`` cancels it.
    """
    cut_off: list[Node] = []
    trace = exc.__traceback__
    while trace is not None:
        node = trace.tb_frame.f_locals.get("self")
        if isinstance(node, Node) and node not in cut_off:
            node.status = RUNNING
            cut_off.append(node)
        trace = trace.tb_next
    return cut_off


def _reason_type(reason: str) -> type[TickInterrupted]:
    """A subclass of :class:`TickInterrupted` whose instances carry ``reason``.

    The C API raises an exception *type* in another thread (it instantiates it there without
    arguments), so the reason travels as the type's default.
    """
    class Interrupted(TickInterrupted):
        def __init__(self, message: str = reason) -> None:
            super().__init__(message)
    Interrupted.__name__ = Interrupted.__qualname__ = "TickInterrupted"
    return Interrupted
