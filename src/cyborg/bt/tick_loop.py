"""Ticking a tree at a fixed rate, with pause, resume, single steps and stop.

    runner = TickLoop(tree, rate_hz=10)
    runner.add_listener(lambda snapshot: print(snapshot.status))
    runner.start()          # ticks in a background thread; or runner.run() to block
    runner.pause()          # ticks stop; RUNNING nodes stay RUNNING (pause(halt=True) halts them)
    runner.step()           # one tick while paused, returns its snapshot
    runner.resume()
    runner.stop()           # ends the loop and halts every RUNNING node

The rate is kept on the tree's clock: ticks are due at ``start + k / rate``. When a tick
overruns its slot the next one starts at once and the schedule restarts from there, so a slow
tick never causes a burst of catch-up ticks. On a simulated or manual clock the runner goes as
fast as the clock lets it, so a long mission can run faster than real time.

The loop ticks anything :class:`Tickable`: a :class:`~cyborg.bt.tree.Tree`, or a machine that
ticks one of several trees (a mode machine, :mod:`cyborg.modes`).

Between two ticks the loop also runs the tree's services (:mod:`cyborg.bt.service_runner`):
when one is due before the next tick, it sleeps until then on the same clock, runs the due
services in the ticking thread, and goes back to sleep, so a service's interval holds even
when it is shorter than the tick period. While paused, services do not run either. Service
listeners (:meth:`TickLoop.add_service_listener`) hear of each such run, and of a halt that
stopped services, as tick listeners hear of ticks.

**A tick that does not end.** Nothing a node does may take away the stop. A tick (or a services
run) longer than ``tick_limit`` wall seconds (:data:`TICK_LIMIT` unless told otherwise) is
interrupted (:mod:`cyborg.bt.tick_guard`), reported with the node it was in, and the tree is
halted and the loop paused; interrupt listeners (:meth:`TickLoop.add_interrupt_listener`) hear
why. A halting :meth:`~TickLoop.pause` or a :meth:`~TickLoop.stop` that finds a tick still computing
after :data:`INTERRUPT_AFTER` seconds interrupts it likewise, so the halt follows at once (one
that waits on the robot is waited for: see :mod:`cyborg.bt.tick_guard`).
"""

from __future__ import annotations

import logging
import math
import threading
from collections.abc import Callable
from typing import Generic, Protocol, TypeVar

from cyborg.bt.clock import Clock
from cyborg.bt.hooks import TreeHooks
from cyborg.bt.service_runner import ServiceRunner
from cyborg.bt.snapshot import TickSnapshot
from cyborg.bt.status import RUNNING, TickInterrupted
from cyborg.bt.tick_guard import TickGuard, mark_cut_off

log = logging.getLogger("cyborg.bt")

Listener = Callable[[TickSnapshot], None]
ServiceListener = Callable[[ServiceRunner], None]
InterruptListener = Callable[[str], None]

DEFAULT_RATE = 10.0
"""Ticks per second unless told otherwise, as in 2018."""
TICK_LIMIT = 10.0
"""Wall seconds a tick may take before it is interrupted and the tree halted (more than any
robot call waits for its answer)."""
INTERRUPT_AFTER = 0.1
"""Wall seconds a halt or stop waits for the tick in progress before interrupting it."""


class Tickable(Protocol):
    """What the loop ticks: a :class:`~cyborg.bt.tree.Tree`, or anything that ticks like one."""

    @property
    def clock(self) -> Clock:
        """The clock the ticks are scheduled on."""
        ...

    @property
    def hooks(self) -> TreeHooks:
        """The hooks of the tree that ticks next (released when the loop pauses or stops)."""
        ...

    @property
    def title(self) -> str:
        """A name for the loop's thread."""
        ...

    @property
    def services(self) -> ServiceRunner | None:
        """The services of the tree that ticks next, run between ticks; None when it has none."""
        ...

    def tick(self) -> TickSnapshot:
        """Ticks once; the snapshot goes to the loop's listeners."""
        ...

    def halt(self) -> object:
        """Halts every RUNNING node."""
        ...


T = TypeVar("T", bound=Tickable)


class TickLoop(Generic[T]):
    """Ticks a :class:`~cyborg.bt.tree.Tree` (or another :class:`Tickable`) at ``rate_hz``.

    The default rate is 10 Hz, as in 2018. ``tick_limit`` (wall seconds; None: none) bounds
    a tick, see the module docstring.
    """

    def __init__(self, tree: T, *, rate_hz: float = DEFAULT_RATE,
                 clock: Clock | None = None, tick_limit: float | None = TICK_LIMIT) -> None:
        if not rate_hz > 0:
            raise ValueError(f"the tick rate must be more than 0 Hz, not {rate_hz}")
        if tick_limit is not None and not tick_limit > 0:
            raise ValueError(f"the tick limit must be more than 0 s, not {tick_limit}")
        self.tree = tree
        self.rate_hz = rate_hz
        self.tick_limit = tick_limit
        self._guard = TickGuard()
        self._interrupt_listeners: list[InterruptListener] = []
        self.clock: Clock = clock or tree.clock
        self._listeners: list[Listener] = []
        self._service_listeners: list[ServiceListener] = []
        self._tick_lock = threading.RLock()
        self._state = threading.Condition()
        self._wake = threading.Event()
        self._paused = False
        self._stopped = False
        self._thread: threading.Thread | None = None  # of start()
        self._running_in: threading.Thread | None = None  # the thread in run(), whoever's

    # ------------------------------------------------------------------ observers
    def add_listener(self, listener: Listener) -> Callable[[], None]:
        """Calls ``listener(snapshot)`` after every tick (in the ticking thread).

        Returns a function that removes the listener. A listener that raises is logged and
        kept; the tree keeps ticking.
        """
        self._listeners.append(listener)
        return lambda: self._listeners.remove(listener)

    def add_service_listener(self, listener: ServiceListener) -> Callable[[], None]:
        """Calls ``listener(services)`` when the loop ran or stopped services outside a tick.

        That is after it ran the due services between two ticks (in the ticking thread), and
        after :meth:`pause` with ``halt`` stopped the active ones (in the pausing thread); each
        time under the loop's tick lock, so ``services.states()`` may be read. Services that
        run within a tick are the tick listeners' news (``snapshot.services``). Returns a
        function that removes the listener; one that raises is logged and kept.
        """
        self._service_listeners.append(listener)
        return lambda: self._service_listeners.remove(listener)

    def add_interrupt_listener(self, listener: InterruptListener) -> Callable[[], None]:
        """Calls ``listener(reason)`` after a tick that overran ``tick_limit`` was interrupted.

        The tree is halted and the loop paused by then (:meth:`resume` ticks again); called
        in the ticking thread. Returns a function that removes the listener.
        """
        self._interrupt_listeners.append(listener)
        return lambda: self._interrupt_listeners.remove(listener)

    @property
    def paused(self) -> bool:
        """Whether :meth:`pause` holds the loop (until :meth:`resume`)."""
        return self._paused

    @property
    def stopped(self) -> bool:
        """Whether :meth:`stop` ended the loop, for good."""
        return self._stopped

    # ------------------------------------------------------------------ control
    def pause(self, *, halt: bool = False) -> None:
        """Stops ticking; with ``halt`` also halts the RUNNING nodes (a moving robot stops).

        A tick waiting at a breakpoint is let go first, and ends before the pause. A halt
        interrupts a tick still going after :data:`INTERRUPT_AFTER` seconds.
        """
        with self._state:
            self._paused = True
            self._wake.set()
        self.tree.hooks.release()  # a tick waiting at a breakpoint ends before the pause
        if halt:
            self._lock_ticks("halted")
            try:
                self.tree.halt()
                services = self.tree.services
                if services is not None:
                    self._services_changed(services)
            finally:
                self._tick_lock.release()

    def _lock_ticks(self, why: str) -> None:
        """Takes the tick lock, interrupting a tick that computes past :data:`INTERRUPT_AFTER`.

        A tick that waits (on the robot) is waited for: it ends by itself.
        """
        cpu_before = self._guard.cpu_time()
        if self._tick_lock.acquire(timeout=INTERRUPT_AFTER):
            return
        where = self._guard.where()
        if self._guard.computing(cpu_before, INTERRUPT_AFTER) and \
                self._guard.interrupt(f"{why} while busy{' in ' + where if where else ''}"):
            log.warning("the tick in progress did not end within %g s; interrupted%s so the "
                        "tree can halt", INTERRUPT_AFTER, " in " + where if where else "")
        self._tick_lock.acquire()

    def resume(self) -> None:
        """Ticks again at the set rate."""
        with self._state:
            self._paused = False
            self._state.notify_all()

    def step(self) -> TickSnapshot:
        """Ticks once now, in the calling thread; meant for a paused runner.

        A tick interrupted on its way (a halt or stop came) raises :class:`RuntimeError`.
        """
        try:
            return self._tick()
        except TickInterrupted as exc:
            self._interrupted(exc)
            raise RuntimeError(f"the tick was interrupted: {exc.reason}") from None

    def stop(self, timeout: float | None = 5.0) -> None:
        """Ends the loop and halts every RUNNING node. Waits for a background loop to end.

        ``timeout`` caps the wait, in seconds (``None``: no cap).
        """
        with self._state:
            self._stopped = True
            self._wake.set()
            self._state.notify_all()
        self.tree.hooks.release()
        thread = self._thread or self._running_in
        if thread is not None and thread is not threading.current_thread():
            cpu_before = self._guard.cpu_time()
            first = INTERRUPT_AFTER if timeout is None else min(timeout, INTERRUPT_AFTER)
            thread.join(first)
            if thread.is_alive():
                if self._guard.computing(cpu_before, first):
                    where = self._guard.where()
                    self._guard.interrupt(f"stopped while busy{' in ' + where if where else ''}")
                thread.join(None if timeout is None else max(timeout - first, 0.0))
        if thread is None:
            with self._tick_lock:
                self.tree.halt()

    def replace_tree(self, tree: T) -> T:
        """Ticks ``tree`` from the next tick on, and returns the old one, halted.

        The old tree's RUNNING nodes are halted (their actions cancel) and its hooks move to
        the new tree where the node ids still exist. Used to reload a tree file in place.
        """
        old = self.tree
        old.hooks.release()
        with self._tick_lock:
            old.halt()
            old.hooks.carry_to(tree.hooks)
            self.tree = tree
            if self.clock is old.clock:
                self.clock = tree.clock
        self._wake.set()
        return old

    # ------------------------------------------------------------------ loops
    def start(self, *, max_ticks: int | None = None, until_done: bool = False) -> None:
        """Runs :meth:`run` in a daemon thread; :class:`RuntimeError` if started already."""
        if self._thread is not None:
            raise RuntimeError("the runner is already started")
        self._thread = threading.Thread(target=self.run, name=f"bt:{self.tree.title}",
                                        kwargs={"max_ticks": max_ticks, "until_done": until_done},
                                        daemon=True)
        self._thread.start()

    def join(self, timeout: float | None = None) -> None:
        """Waits for a background loop to end, at most ``timeout`` seconds if given."""
        if self._thread is not None:
            self._thread.join(timeout)

    def run(self, *, max_ticks: int | None = None, until_done: bool = False) -> None:
        """Ticks at the set rate, in the calling thread, until the loop ends.

        It ends when stopped, once ``max_ticks`` ticks are done, or (with ``until_done``) when
        the root returns something other than RUNNING. RUNNING nodes are halted on the way out.
        """
        period = 1.0 / self.rate_hz
        clock = self.clock
        anchor = now = clock.now()  # ticks are due at anchor + slot * period (no drift)
        slot = 0
        done = 0
        ended = threading.Event()
        self._running_in = threading.current_thread()
        if self.tick_limit is not None:
            threading.Thread(target=self._watch, args=(self.tick_limit, ended), daemon=True,
                             name=f"bt-watch:{self.tree.title}").start()
        try:
            while True:
                with self._state:
                    while self._paused and not self._stopped:
                        self._state.wait()
                        anchor, slot = clock.now(), 0
                    if self._stopped:
                        break
                    self._wake.clear()
                try:
                    snapshot = self._tick()
                except TickInterrupted as exc:
                    self._interrupted(exc)
                    continue
                done += 1
                if max_ticks is not None and done >= max_ticks:
                    break
                if until_done and snapshot.status is not RUNNING:
                    break
                slot += 1
                due = anchor + slot * period
                before, now = now, clock.now()
                if due < now or now < before:  # overran, or the clock went back (a restarted
                    anchor, slot, due = now, 0, now  # simulation): restart the schedule
                try:
                    self._sleep_until(due)
                except TickInterrupted as exc:  # in services run between two ticks
                    self._interrupted(exc)
        finally:
            ended.set()
            with self._tick_lock:
                self.tree.halt()

    def _watch(self, limit: float, ended: threading.Event) -> None:
        """Interrupts a tick (or services run) that takes longer than ``limit`` wall seconds."""
        while not ended.wait(min(limit / 4, 0.25)):
            busy = self._guard.busy_for()
            if busy is not None and busy > limit:
                where = self._guard.where()
                self._guard.interrupt(f"the tick ran longer than its limit of {limit:g} s"
                                      f"{', in ' + where if where else ''}")

    def _interrupted(self, exc: TickInterrupted) -> None:
        """After an interrupted tick: halts and pauses on an overrun, and tells the listeners.

        An interruption asked for by a halt or stop needs nothing more: they halt the tree.
        """
        reason = self._guard.leave() or exc.reason
        if self._paused or self._stopped:
            log.info("the tick was interrupted: %s", reason)
            return
        log.error("%s: interrupted; the tree is halted and ticking paused", reason)
        with self._state:
            self._paused = True
        with self._tick_lock:
            self.tree.halt()
        for listener in list(self._interrupt_listeners):
            try:
                listener(reason)
            except Exception:
                log.exception("interrupt listener %r raised", listener)

    def _sleep_until(self, due: float) -> None:
        """Sleeps until the tick due at ``due``, running the services due before it."""
        clock, wake = self.clock, self._wake
        while not wake.is_set():
            services = self.tree.services
            next_run = math.inf if services is None else services.next_due()
            if next_run >= due:
                break
            clock.sleep_until(next_run, wake)
            if wake.is_set():
                return
            with self._tick_lock:
                if self.tree.services is services and services is not None:
                    self._guard.enter()
                    try:
                        services.run_due(clock.now())
                    finally:
                        self._guard.leave()
                    self._services_changed(services)
        clock.sleep_until(due, wake)

    def _services_changed(self, services: ServiceRunner) -> None:
        for listener in list(self._service_listeners):
            try:
                listener(services)
            except Exception:
                log.exception("service listener %r raised", listener)

    def _tick(self) -> TickSnapshot:
        """Ticks once under the tick lock, interruptibly, then tells the listeners."""
        with self._tick_lock:
            self._guard.enter()
            try:
                snapshot = self.tree.tick()
            except TickInterrupted as exc:  # before a halting thread may take the lock:
                mark_cut_off(exc)  # its halt must reach the nodes cut off
                raise
            finally:
                self._guard.leave()
        for listener in list(self._listeners):
            try:
                listener(snapshot)
            except Exception:
                log.exception("tick listener %r raised", listener)
        return snapshot
