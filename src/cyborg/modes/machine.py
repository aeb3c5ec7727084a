"""The mode machine: one tree per mode, ticking the current mode's tree, switching on rules.

:class:`ModeMachine` holds a built :class:`~cyborg.bt.tree.Tree` for every mode of a
:class:`~cyborg.modes.spec.MachineSpec`. It does no I/O and takes its time from the trees'
clock. What happens, and in which order:

* :meth:`~ModeMachine.tick` ticks the current mode's tree once, then tries the ``when``
  transitions that may leave the mode, **in the order of the file**; the first whose condition
  (and guard) holds fires. If none does and the mode's ``max_time`` has run out, it goes to its
  ``then``. At most one transition follows a tick.
* :meth:`~ModeMachine.fire_event` tries the transitions on that event, in order;
  :meth:`~ModeMachine.request` those marked ``on_request`` that lead to the mode asked for.
  Both answer with a :class:`~cyborg.modes.records.Decision` saying what happened or why not.
* **Dwell.** Until a mode has run ``min_dwell`` seconds (its own, else the file's), conditions,
  events and requests cannot leave it; a refused event is not kept for later. ``max_time`` and
  forces are not held back by the dwell.
* **Hold.** :meth:`~ModeMachine.hold` is the operator's block: while held, nothing but a force
  leaves the current mode (no condition, event, request or timeout). The hold stays on after a
  force, on the forced mode, until released.
* **Force.** :meth:`~ModeMachine.force` enters any mode at once, past guards, dwell and hold.

A mode's time starts when it is entered; the initial mode's at the machine's first tick (or
first event, request or force).

**Leaving a mode** halts its tree (:meth:`Tree.halt <cyborg.bt.tree.Tree.halt>`: every RUNNING
node's ``on_halt`` runs exactly once, deepest first, so a running MoveTo cancels its goal)
before anything else happens, and **entering** one starts its tree fresh: its tree and node
memories are emptied, so it begins as on its first tick. Only the blackboard's global scope
(and the resources) is shared between the modes' trees. Two modes may hold the same
:class:`~cyborg.bt.tree.Tree` (:func:`cyborg.modes.build_machine` builds a tree several modes
name once): the switch between them halts it and empties its memories all the same.

Each transition is kept in :attr:`~ModeMachine.history` and handed to the listeners added with
:meth:`~ModeMachine.add_listener`, in the thread that caused it (the ticking thread, or the one
that asked), after the new mode is current. A lock keeps switches out of ticks: a request made
while a tick runs waits for that tick to end.

**Ticking it.** A machine offers what :class:`cyborg.bt.TickLoop` needs of a tree (``tick``,
``halt``, ``clock``, ``hooks``, ``title``), so ``TickLoop(machine, rate_hz=10)`` runs it as it
runs a tree; pausing with ``halt=True`` or stopping halts the current mode's tree.
"""

from __future__ import annotations

import logging
import threading
from collections import deque
from collections.abc import Callable, Mapping
from typing import Any

from cyborg.bt.blackboard import Blackboard
from cyborg.bt.clock import Clock
from cyborg.bt.hooks import TreeHooks
from cyborg.bt.node import Node
from cyborg.bt.service_runner import ServiceRunner
from cyborg.bt.snapshot import TickSnapshot
from cyborg.bt.tree import Tree
from cyborg.modes.records import Decision, ModeTick, Transition, Trigger
from cyborg.modes.spec import MachineSpec, TransitionSpec

log = logging.getLogger("cyborg.modes")

TransitionListener = Callable[[Transition], None]

HISTORY = 256
"""Transitions kept in :attr:`ModeMachine.history` (the oldest are dropped first)."""


class ModeMachine:
    """Runs one tree per mode; see the module docstring for the rules."""

    def __init__(self, spec: MachineSpec, trees: Mapping[str, Tree], *,
                 clock: Clock | None = None, history: int = HISTORY) -> None:
        missing = sorted(set(spec.modes) - set(trees))
        if missing:
            raise ValueError(f"no tree given for the modes {', '.join(missing)}")
        first = trees[spec.initial]
        shared = first.blackboard.globals
        if any(trees[name].blackboard.globals is not shared for name in spec.modes):
            raise ValueError("the modes' trees must share one global scope (one dict)")
        self.spec = spec
        self.trees: dict[str, Tree] = {name: trees[name] for name in spec.modes}
        self.clock: Clock = clock or first.clock
        self.globals: dict[str, Any] = shared
        """The blackboard's global scope, which every mode's tree reads and writes."""
        self.history: deque[Transition] = deque(maxlen=history)
        """The latest transitions, oldest first."""
        self.transition_count = 0
        """How many transitions the machine has made."""
        self.last: ModeTick | None = None
        """The machine's snapshot of its latest tick."""
        self._mode = spec.initial
        self._entered: float | None = None
        self._held = False
        self._lock = threading.RLock()
        self._listeners: list[TransitionListener] = []

    # ------------------------------------------------------------------ state
    @property
    def mode(self) -> str:
        """The current mode's name."""
        return self._mode

    @property
    def tree(self) -> Tree:
        """The current mode's tree."""
        return self.trees[self._mode]

    @property
    def held(self) -> bool:
        """Whether the operator holds the current mode (see :meth:`hold`)."""
        return self._held

    @property
    def hooks(self) -> TreeHooks:
        """The current mode's tree's hooks (breakpoints, forced statuses)."""
        return self.tree.hooks

    @property
    def services(self) -> ServiceRunner | None:
        """The current mode's tree's services, which the tick loop runs between ticks."""
        return self.tree.services

    @property
    def blackboard(self) -> Blackboard:
        """The current mode's tree's blackboard (its global scope is :attr:`globals`)."""
        return self.tree.blackboard

    @property
    def title(self) -> str:
        """The machine's name: its mode file."""
        return self.spec.source

    @property
    def entered(self) -> float | None:
        """The clock time at which the current mode was entered; None before the start."""
        return self._entered

    def time_in_mode(self) -> float:
        """Seconds on the clock since the current mode was entered (0 before the start)."""
        return 0.0 if self._entered is None else self.clock.now() - self._entered

    def add_listener(self, listener: TransitionListener) -> Callable[[], None]:
        """Calls ``listener(transition)`` after every transition; returns its remover.

        A listener that raises is logged and kept.
        """
        self._listeners.append(listener)
        return lambda: self._listeners.remove(listener)

    # ------------------------------------------------------------------ ticking
    def tick(self) -> TickSnapshot:
        """Ticks the current mode's tree, then its transitions; returns the tree's snapshot.

        :attr:`last` tells which mode ticked and the transition that followed, if any.
        """
        with self._lock:
            self._start()
            mode = self._mode
            snapshot = self.trees[mode].tick()
            taken = self._after_tick()
            self.last = ModeTick(mode, snapshot, taken)
            return snapshot

    def halt(self) -> list[Node]:
        """Halts the current mode's tree (the mode stays); returns the nodes halted."""
        with self._lock:
            return self.tree.halt()

    def _after_tick(self) -> Transition | None:
        if self._held:
            return None
        mode = self.spec.modes[self._mode]
        elapsed = self.time_in_mode()
        if elapsed >= mode.min_dwell:
            for transition in self.spec.transitions:
                when = transition.when
                if when is not None and transition.leaves(mode.name) \
                        and when.holds(self.globals) and self._guard_holds(transition):
                    return self._switch(transition.target, transition.reason
                                        or f"when {when.source}", Trigger.CONDITION,
                                        transition.number)
        if mode.max_time is not None and mode.then is not None and elapsed >= mode.max_time:
            return self._switch(mode.then, f"max_time {mode.max_time:g} s ran out",
                                Trigger.TIMEOUT)
        return None

    # ------------------------------------------------------------------ asking
    def fire_event(self, name: str) -> Decision:
        """Takes the first transition on event ``name`` that may leave the current mode."""
        with self._lock:
            self._start()
            mode = self._mode
            if not any(t.event == name for t in self.spec.transitions):
                return Decision(False, f"no transition takes the event {name!r}")
            candidates = [t for t in self.spec.transitions
                          if t.event == name and t.leaves(mode)]
            if not candidates:
                return Decision(False, f"no transition takes the event {name!r} in mode "
                                       f"{mode!r}")
            return self._take(candidates, f"event {name}", Trigger.EVENT)

    def request(self, mode: str, reason: str = "") -> Decision:
        """Enters ``mode`` if an ``on_request`` transition allows it now.

        Guards, the dwell time and the hold are honoured. Asking for the current mode is
        accepted and changes nothing.
        """
        with self._lock:
            self._start()
            refused = self._unknown(mode)
            if refused is not None:
                return refused
            current = self._mode
            if mode == current:
                return Decision(True, f"already in mode {mode!r}")
            allowed = [t for t in self.spec.transitions if t.on_request and t.leaves(current)]
            candidates = [t for t in allowed if t.target == mode]
            if not candidates:
                others = sorted({t.target for t in allowed})
                where = (f"; from here a request may enter {', '.join(map(repr, others))}"
                         if others else "; no request may leave it")
                return Decision(False, f"no transition lets a request go from mode "
                                       f"{current!r} to {mode!r}{where}")
            return self._take(candidates, reason or "requested", Trigger.REQUEST)

    def force(self, mode: str, reason: str = "") -> Decision:
        """Enters ``mode`` at once, whatever the transitions, guards, dwell or hold say."""
        with self._lock:
            self._start()
            refused = self._unknown(mode)
            if refused is not None:
                return refused
            if mode == self._mode:
                return Decision(True, f"already in mode {mode!r}")
            transition = self._switch(mode, reason or "forced by the operator", Trigger.FORCE)
            return Decision(True, f"forced into mode {mode!r}", transition)

    def hold(self, on: bool) -> None:
        """Holds the current mode (True) until released (False): only a force leaves it."""
        with self._lock:
            self._held = bool(on)

    # ------------------------------------------------------------------ internals
    def _start(self) -> None:
        if self._entered is None:
            self._entered = self.clock.now()

    def _unknown(self, mode: str) -> Decision | None:
        if mode in self.spec.modes:
            return None
        return Decision(False, f"there is no mode {mode!r}; modes: "
                               f"{', '.join(map(repr, self.spec.modes))}")

    def _take(self, candidates: list[TransitionSpec], reason: str,
              trigger: Trigger) -> Decision:
        mode = self.spec.modes[self._mode]
        if self._held:
            return Decision(False, f"mode {mode.name!r} is held by the operator; release it "
                                   "or force a mode")
        elapsed = self.time_in_mode()
        if elapsed < mode.min_dwell:
            return Decision(False, f"mode {mode.name!r} has run {elapsed:.3g} s of its minimum "
                                   f"{mode.min_dwell:g} s (min_dwell)")
        for transition in candidates:
            if self._guard_holds(transition):
                taken = self._switch(transition.target, transition.reason or reason, trigger,
                                     transition.number)
                return Decision(True, f"entered mode {transition.target!r}", taken)
        guards = "; ".join(f"{t.label}: guard {t.guard.source!r} is false"
                           + (f" ({t.guard.last_error})" if t.guard.last_error else "")
                           for t in candidates if t.guard is not None)
        return Decision(False, f"refused: {guards}")

    def _guard_holds(self, transition: TransitionSpec) -> bool:
        return transition.guard is None or transition.guard.holds(self.globals)

    def _switch(self, target: str, reason: str, trigger: Trigger,
                number: int | None = None) -> Transition:
        """Halts the current tree, empties the next one's memories, and makes it current."""
        source = self._mode
        self.trees[source].halt()
        _fresh(self.trees[target].blackboard)
        now = self.clock.now()
        self._mode, self._entered = target, now
        transition = Transition(source, target, reason, now, trigger, number)
        self.history.append(transition)
        self.transition_count += 1
        log.info("mode %s -> %s (%s)", source, target, reason)
        for listener in list(self._listeners):
            try:
                listener(transition)
            except Exception:
                log.exception("mode transition listener %r raised", listener)
        return transition


def _fresh(blackboard: Blackboard) -> None:
    """Empties a tree's tree and node memories in place (nodes keep references to them)."""
    for scope in (*blackboard.trees.values(), *blackboard.nodes.values()):
        scope.clear()
