"""A node's extension points: what runs around its tick, and the record each tick leaves.

Every node has two slots, empty unless someone fills them, as BehaviorTree.CPP's pre- and
post-tick callbacks::

    node.pre_tick = callback     # callback(node) -> Status | None, before the node ticks
    node.post_tick = callback    # callback(node, status) -> Status | None, after it returned

* **pre_tick** returns ``None`` to let the node tick as usual, or a status to return instead,
  without ticking (nothing below the node ticks either). It runs in the ticking thread and may
  block it: a breakpoint waits here.
* **post_tick** sees the status the node returned (ticked, or substituted by ``pre_tick``) and
  returns ``None`` to keep it or another status to replace it.

The tree's hooks (:mod:`cyborg.bt.hooks`: disable, force, breakpoints) fill these slots, and a
timed tree (:attr:`Tree.timing <cyborg.bt.tree.Tree.timing>`) sets :attr:`~ExtensionPoints.timed`
on its nodes; nothing replaces a node's ``execute``. While no node of a tree uses a slot or is
timed, :meth:`Node.execute <cyborg.bt.node.Node.execute>` pays one test of
:attr:`TickRecord.hooked` for all of this; a node that uses one (it is in that set) goes through
:meth:`ExtensionPoints._execute_hooked`.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from time import perf_counter
from typing import TYPE_CHECKING, Any, ClassVar, Self

from cyborg.bt.status import RUNNING, Status

_rehooking = threading.Lock()  # slots change from any thread (a monitor's, the ticking one)


class TickRecord:
    """What one tick of a tree leaves behind; shared by every node of that tree.

    The tree replaces the lists at the start of each tick, so a finished tick's lists can be
    handed to a snapshot without copying.
    """

    __slots__ = ("durations", "halted", "hooked", "now", "paused", "running", "visits")

    def __init__(self) -> None:
        self.now = 0.0
        """Time of the current tick, in seconds of the tree's clock."""
        # (The nodes are typed Any: this module is below cyborg.bt.node and cannot name Node.)
        self.visits: list[tuple[Any, Status]] = []
        """Every node executed in this tick, in completion order (children before parents)."""
        self.running: list[Any] = []
        """Nodes that returned RUNNING in this tick, deepest first."""
        self.halted: list[Any] = []
        """Nodes halted in this tick, deepest first."""
        self.durations: dict[int, float] = {}
        """Wall time of each visit (index into ``visits``), when the tree is timed."""
        self.paused = 0.0
        """Seconds timed nodes have spent in pre-tick callbacks (a breakpoint waits there),
        ever; timings leave that time out."""
        self.hooked: set[Any] = set()
        """The tree's nodes with a pre- or post-tick callback, or timed. Every node tests it
        as it executes (whether it is empty, then whether the node is in it): a read of one
        class's slot, where a flag of each node would be read from many node classes at the
        same place, which Python 3.11 does slowly."""


class ExtensionPoints:
    """The slots of :class:`~cyborg.bt.node.Node` (its base class); see the module docstring."""

    _pre_tick: Callable[[Self], Status | None] | None = None
    _post_tick: Callable[[Self, Status], Status | None] | None = None
    _timed: bool = False

    if TYPE_CHECKING:  # what the slow path uses of the node; cyborg.bt.node.Node defines it
        _record: TickRecord
        status: Status | None
        _starts: ClassVar[bool]
        _ends: ClassVar[bool]

        def on_start(self) -> None:
            """Declared here for the slow path: see :meth:`~cyborg.bt.node.Node.on_start`."""

        def tick(self) -> Status:
            """Declared here for the slow path: see :meth:`~cyborg.bt.node.Node.tick`."""

        def halt(self) -> None:
            """Declared here for the slow path: see :meth:`~cyborg.bt.node.Node.halt`."""

        def _end(self, status: Status) -> None: ...
        def _coerce(self, value: object) -> Status: ...
        def _raised(self, exc: Exception, during: str = "tick") -> Status: ...

    @property
    def pre_tick(self) -> Callable[[Self], Status | None] | None:
        """Called as ``pre_tick(node)`` each time the node is about to tick; ``None``: nothing.

        Return ``None`` to let the node tick, or a status to return without ticking. A
        substituted SUCCESS, FAILURE or ERROR halts the node first if it was RUNNING, as a
        parent that stops ticking it would; a substituted RUNNING keeps the activation going,
        and the tree halts what is left RUNNING below it. The time spent here is left out of
        the tree's timings. One callback per slot; to chain, call the previous one from yours::

            class Probe(Action):
                def tick(self) -> Status:
                    return SUCCESS

            probe = Probe()  # (built by the loader, in a tree: ``tree.by_uid[...]``)
            probe.pre_tick = lambda node: FAILURE if node.blackboard.get("skip") else None

        :class:`~cyborg.bt.hooks.TreeHooks` takes this slot while it hooks the node, calls the
        callback it found there after its own, and puts it back when the hook is cleared.
        """
        return self._pre_tick

    @pre_tick.setter
    def pre_tick(self, callback: Callable[[Self], Status | None] | None) -> None:
        self._pre_tick = callback
        self._rehook()

    @property
    def post_tick(self) -> Callable[[Self, Status], Status | None] | None:
        """Called as ``post_tick(node, status)`` each time the node has returned ``status``.

        ``None`` (the default): nothing is called. Return ``None`` (or ``status``) to keep the
        result, or another status to make it the node's result: the parent sees it, the
        snapshot records it, and a RUNNING node made to finish ends its activation (``on_end``
        runs with the new status). A finished node made RUNNING stays active.
        :class:`~cyborg.bt.hooks.TreeHooks` forces results here, calling the callback it found
        first.
        """
        return self._post_tick

    @post_tick.setter
    def post_tick(self, callback: Callable[[Self, Status], Status | None] | None) -> None:
        self._post_tick = callback
        self._rehook()

    @property
    def timed(self) -> bool:
        """Whether each visit's wall time goes into the tick's snapshot.

        The time covers the node and its subtree, pre-tick time left out. The tree sets this on
        every node from :attr:`Tree.timing <cyborg.bt.tree.Tree.timing>` between ticks; set
        that instead.
        """
        return self._timed

    @timed.setter
    def timed(self, on: bool) -> None:
        self._timed = bool(on)
        self._rehook()

    # ----------------------------------------------------------------- the slow path
    def _rehook(self) -> None:
        """Joins or leaves the record's ``hooked`` set, as the slots now say."""
        record: TickRecord | None = getattr(self, "_record", None)
        if record is None:
            return  # not bound yet: `Node.bind` calls this again
        with _rehooking:
            if self._pre_tick is not None or self._post_tick is not None or self._timed:
                record.hooked.add(self)
            else:
                record.hooked.discard(self)

    def _execute_hooked(self: Self) -> Status:
        """``execute`` through the slots, for a node that uses one or is timed.

        Runs the pre-tick callback, the tick (or the status it substituted), the post-tick
        callback, and takes the visit's time when timed.

        Four frames per tree level (``execute``, this, ``_tick_once``, ``tick``): the budget
        of :data:`cyborg.bt.limits.FRAMES_PER_LEVEL`; the callbacks return before the tick.
        """
        record = self._record
        timed = self._timed
        if timed:
            started, paused = perf_counter(), record.paused
        pre = self._pre_tick
        substitute = None
        if pre is not None:
            if timed:
                entered = perf_counter()
                substitute = pre(self)
                record.paused += perf_counter() - entered
            else:
                substitute = pre(self)
        status = self._tick_once() if substitute is None else self._skip(substitute)
        post = self._post_tick
        if post is not None:
            replaced = post(self, status)
            if replaced is not None and replaced is not status:
                self._replace_result(status, replaced)
                status = replaced
        if timed:
            elapsed = perf_counter() - started - (record.paused - paused)
            record.durations[len(record.visits) - 1] = elapsed
        return status

    def _tick_once(self) -> Status:
        """One visit without the slots: the steps ``Node.execute`` takes inline."""
        try:
            if self._starts and self.status is not RUNNING:
                self.on_start()
            status = self.tick()
            if status.__class__ is not Status:
                status = self._coerce(status)
        except Exception as exc:
            status = self._raised(exc)
        self.status = status
        record = self._record
        record.visits.append((self, status))
        if status is RUNNING:
            record.running.append(self)
        elif self._ends:
            self._end(status)
        return status

    def _skip(self, status: Status) -> Status:
        """Returns ``status`` without ticking (a pre-tick substitute).

        A finished one (a disabled node) halts the node and its RUNNING subtree; a RUNNING one
        keeps the activation, and what is not reached below is halted by the tree.
        """
        record = self._record
        if status is not RUNNING:
            self.halt()
        self.status = status
        record.visits.append((self, status))
        if status is RUNNING:
            record.running.append(self)
        return status

    def _replace_result(self, original: Status, forced: Status) -> None:
        """Makes ``forced`` the result of the visit that just returned ``original``.

        This node's entries are the last ones appended to the tick record (children finish
        first), so they are patched in place; a RUNNING node forced to finish ends normally.
        """
        record = self._record
        self.status = forced
        record.visits[-1] = (self, forced)
        if original is RUNNING:
            record.running.pop()
            if self._ends:
                self._end(forced)
        elif forced is RUNNING:
            record.running.append(self)
