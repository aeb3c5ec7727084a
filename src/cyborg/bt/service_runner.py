"""Running a tree's services: activation, the timers on the tree's clock, deactivation.

The :class:`~cyborg.bt.tree.Tree` holds a :class:`ServiceRunner` when any of its composites
carries services (``tree.services``; ``None`` otherwise, and then nothing here costs a tick
anything). The tree calls it at three points, all on the thread that ticks:

* **before each tick**, :meth:`ServiceRunner.run_due` runs every active service whose time has
  come, so the tick's conditions read fresh keys;
* **after each tick**, :meth:`ServiceRunner.after_tick` deactivates the services of every
  composite whose activation ended in the tick (it completed, or was halted), deepest first,
  then activates those of every composite that became RUNNING, outermost first;
* **on** :meth:`Tree.halt <cyborg.bt.tree.Tree.halt>`, :meth:`ServiceRunner.stop_all`
  deactivates every active service.

Between ticks the :class:`~cyborg.bt.tick_loop.TickLoop` asks :meth:`ServiceRunner.next_due`
and, when a service is due before the next tick, sleeps until then on the tree's clock and
runs it: a service with a 0.1 s interval on a 1 Hz tree runs at 10 Hz, on a simulated clock
too. Each call of :meth:`run_due` runs a due service once; its next due time is the last one
plus an interval, or, when that has passed already (a slow tick, a clock that jumped), now plus
an interval: a late service never runs in a burst to catch up.
"""

from __future__ import annotations

import logging
import math
import random
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from cyborg.bt.services import MIN_INTERVAL, Service, ServiceBoard
from cyborg.bt.status import RUNNING

if TYPE_CHECKING:
    from cyborg.bt.blackboard import Blackboard
    from cyborg.bt.node import Node

log = logging.getLogger("cyborg.bt")


@dataclass(frozen=True)
class ServiceState:
    """One attached service as a monitor sees it after a tick."""

    composite: str
    """The stable id of the composite it hangs on."""
    service: str
    """Its registered name (unique on its composite)."""
    active: bool
    """Whether it runs now (its composite is RUNNING and it has not failed since)."""
    last_run: float | None
    """Tree-clock time of its last run; ``None`` before the first."""
    runs: int
    """How many times it has run, ever."""
    wrote: dict[str, str] = field(default_factory=dict)
    """Each blackboard key it has written, with its last value as short text."""
    error: str | None = None
    """What it last raised (``"RuntimeError: ..."``), if it ever raised."""

    def to_json(self) -> dict[str, Any]:
        """``{"composite", "service", "active", "last_run", "runs", "wrote", "error"}``."""
        return {"composite": self.composite, "service": self.service, "active": self.active,
                "last_run": self.last_run, "runs": self.runs, "wrote": dict(self.wrote),
                "error": self.error}


class ScheduledService:
    """One service on one composite, with its timer and its record."""

    def __init__(self, service: Service, composite: Node, blackboard: Blackboard,
                 position: int, declaration: str = "") -> None:
        self.service = service
        self.composite = composite
        self.declaration = declaration or service.name
        """The call as written in the ``services`` property."""
        self.timing = service.timing
        self.board = ServiceBoard(blackboard)
        self.random = random.Random(f"{composite.uid}#{position}:{service.name}")
        """This service's own stream for the deviation; seeded, so runs repeat exactly."""
        self.active = False
        self.due = math.inf
        """Tree-clock time of the next run; kept across activations when the timer is not
        restarted, ``inf`` before the first activation."""
        self.last_run: float | None = None
        self.runs = 0
        self.error: str | None = None
        self._last_exception: tuple[type, tuple[Any, ...]] | None = None

    def after(self, time: float) -> float:
        """The due time one interval after ``time``, rounded to the nanosecond.

        The rounding keeps sums of intervals such as 0.1 from drifting past the tick they
        are meant to fall on (twenty of them make 2.0, not 2.0000000000000004). It is never
        less than :data:`~cyborg.bt.services.MIN_INTERVAL` after ``time``, even for timing
        made in Python without the load's checks.
        """
        return max(round(time + self.interval(), 9), time + MIN_INTERVAL)

    def interval(self) -> float:
        """One interval, with the deviation drawn when there is one."""
        timing = self.timing
        if not timing.deviation:
            return timing.interval
        return timing.interval + self.random.uniform(-timing.deviation, timing.deviation)

    def activate(self, now: float) -> None:
        """Starts the service: the timer, :meth:`Service.on_activate`, the activation run."""
        self.active = True
        if self.timing.restart_on_activation or self.due == math.inf:
            self.due = self.after(now)
        if self._call("on_activate", now) and self.timing.run_on_activation:
            self._run(now)

    def run_if_due(self, now: float) -> None:
        """Runs the service once if its time has come, and sets the next due time."""
        if now < self.due:
            return
        due = self.after(self.due)
        self.due = due if due > now else self.after(now)
        self._run(now)

    def deactivate(self, now: float) -> None:
        """Stops the service: :meth:`Service.on_deactivate` runs once; the timer stops."""
        if self.active:
            self.active = False
            self._call("on_deactivate", now)

    def _run(self, now: float) -> None:
        self.last_run = now
        self.runs += 1
        self.board.changed = True
        self._call("run", now)

    def _call(self, method: str, now: float) -> bool:
        """Calls one of the service's methods; on an exception, reports it and stops it."""
        board = self.board
        board.now = now
        try:
            getattr(self.service, method)(board)
            return True
        except Exception as exc:
            self._report(exc, method)
            if method != "on_deactivate":
                self.deactivate(now)
            return False

    def _report(self, exc: Exception, method: str) -> None:
        self.error = f"{type(exc).__name__}: {exc}"
        self.board.changed = True
        composite = self.composite
        seen = (type(exc), exc.args)
        if seen == self._last_exception:
            log.debug("service %s on %s raised again in %s: %r", self.service.name,
                      composite.uid, method, exc)
            return
        self._last_exception = seen
        log.error("service %s on composite %s (%s, %s) raised in %s; it is stopped until the "
                  "composite starts again, and the tree goes on", self.service.name,
                  composite.uid, composite.label, composite.name, method, exc_info=exc)

    def state(self) -> ServiceState:
        """Its state now, for snapshots."""
        return ServiceState(self.composite.uid, self.service.name, self.active, self.last_run,
                            self.runs, self.board.wrote, self.error)


class ServiceRunner:
    """The services of one tree, grouped by composite; see the module docstring."""

    def __init__(self, services: Sequence[ScheduledService]) -> None:
        self.services = list(services)
        """Every attached service, in tree order."""
        self._by_node: dict[Node, list[ScheduledService]] = {}
        for scheduled in self.services:
            self._by_node.setdefault(scheduled.composite, []).append(scheduled)
        self._active: list[Node] = []
        """Composites whose services are activated, outermost first."""
        self._states: tuple[ServiceState, ...] | None = None
        self._changed = True
        """Whether a service started or stopped since :meth:`states` was last built (a
        service writes only while active, so only active ones need a look besides)."""

    def of(self, composite: Node) -> list[ScheduledService]:
        """The services attached to ``composite`` (empty for any other node)."""
        return list(self._by_node.get(composite, ()))

    @property
    def active(self) -> list[Node]:
        """The composites whose services are activated now, outermost first."""
        return list(self._active)

    def after_tick(self, running: list[Node], halted: list[Node], now: float) -> None:
        """Ends the activations the tick ended, then starts those it began."""
        if not (running or self._active):
            return
        if self._active:
            ended = set(halted) if halted else ()
            for composite in reversed(list(self._active)):  # innermost first
                if composite.status is not RUNNING or composite in ended:
                    self._deactivate(composite, now)
        by_node = self._by_node
        for node in reversed(running):  # running is deepest first
            if node in by_node and node not in self._active:
                self._activate(node, now)

    def stop_all(self, now: float) -> None:
        """Deactivates every active service, innermost composite first (the tree halted)."""
        for composite in reversed(list(self._active)):
            self._deactivate(composite, now)

    def run_due(self, now: float) -> None:
        """Runs each active service whose time has come, once, outermost composite first.

        A composite found no longer RUNNING (halted outside a tick) is deactivated instead.
        """
        if not self._active:
            return
        for composite in list(self._active):
            if composite.status is not RUNNING:
                self._deactivate(composite, now)
                continue
            for scheduled in self._by_node[composite]:
                if scheduled.active:
                    scheduled.run_if_due(now)

    def next_due(self) -> float:
        """Tree-clock time at which the next active service is due; ``inf`` when none is."""
        due = math.inf
        for composite in self._active:
            for scheduled in self._by_node[composite]:
                if scheduled.active and scheduled.due < due:
                    due = scheduled.due
        return due

    def states(self) -> tuple[ServiceState, ...]:
        """Every attached service's state, in tree order; rebuilt only after a change.

        While no service is active this costs a test, however many are attached.
        """
        changed = self._changed
        for composite in self._active:
            for scheduled in self._by_node[composite]:
                if scheduled.board.changed:
                    scheduled.board.changed = False
                    changed = True
        if changed or self._states is None:
            self._changed = False
            for scheduled in self.services:
                scheduled.board.changed = False
            self._states = tuple(scheduled.state() for scheduled in self.services)
        return self._states

    def _activate(self, composite: Node, now: float) -> None:
        self._active.append(composite)
        self._active.sort(key=_index)
        self._changed = True
        for scheduled in self._by_node[composite]:
            scheduled.activate(now)

    def _deactivate(self, composite: Node, now: float) -> None:
        self._active.remove(composite)
        self._changed = True
        for scheduled in reversed(self._by_node[composite]):
            scheduled.deactivate(now)


def _index(node: Node) -> int:
    return node.index
