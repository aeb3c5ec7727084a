"""A running behaviour tree: one root, a clock, a blackboard, and the tick.

:meth:`Tree.tick` ticks the root once and then enforces the halting rule:

    A node that was RUNNING and is not reached in the next tick is halted in that tick,
    deepest first, and its ``on_halt`` runs exactly once.

The same pass also halts a node left RUNNING under a parent that itself completed (a custom
composite that forgot its child), so an abandoned action can always cancel what it started.
Every tick returns a :class:`~cyborg.bt.snapshot.TickSnapshot`.

**Services.** When composites carry services (:mod:`cyborg.bt.services`), :attr:`Tree.services`
runs them: due ones before each tick, activations and deactivations after it and on
:meth:`Tree.halt`. A tree without services pays three `is None` tests per tick for this.

**Timing.** ``Tree(..., timing=True)``, or ``tree.timing = True`` at any time from any thread,
makes every tick from the next one on record each visit's wall time in its snapshot
(:attr:`~cyborg.bt.snapshot.TickSnapshot.visit_durations`); a change is applied when a tick
begins, never inside one, so a tick is timed completely or not at all.
"""

from __future__ import annotations

from collections.abc import Iterator
from time import perf_counter

from cyborg.bt.blackboard import Blackboard
from cyborg.bt.clock import Clock, MonotonicClock
from cyborg.bt.hooks import TreeHooks
from cyborg.bt.node import Node, TickRecord
from cyborg.bt.resources import requirements_of
from cyborg.bt.service_runner import ServiceRunner
from cyborg.bt.snapshot import TickSnapshot, TreeStructure
from cyborg.bt.status import RUNNING, Status


class Tree:
    """A tree of live nodes ready to tick. Build one with :func:`cyborg.bt.load_tree`."""

    def __init__(self, root: Node, *, record: TickRecord, blackboard: Blackboard,
                 clock: Clock | None = None, source: str = "", tree_id: str = "",
                 title: str = "", timing: bool = False,
                 services: ServiceRunner | None = None) -> None:
        self.root = root
        self.blackboard = blackboard
        self.clock: Clock = clock or MonotonicClock()
        self.source = source
        self.tree_id = tree_id
        self.title = title
        self.ticks = 0
        """Number of ticks done so far."""
        self.last: TickSnapshot | None = None
        self._record = record
        self._running: list[Node] = []
        self.nodes: list[Node] = list(root.walk())
        """Every node, depth first, pre-order; ``nodes[i].index == i``."""
        for index, node in enumerate(self.nodes):
            node.index = index
        self.by_uid: dict[str, Node] = {node.uid: node for node in self.nodes}
        self._structure: TreeStructure | None = None
        self.services = services
        """Runs the services attached to composites; ``None`` when the tree has none."""
        self.hooks = TreeHooks(self.nodes, self)
        """Per-node control: disable, force, breakpoints (see :mod:`cyborg.bt.hooks`)."""
        self._timing = False  # what the nodes do now
        self._timing_wanted = bool(timing)  # what the next tick does
        if timing:
            self._apply_timing()

    def __iter__(self) -> Iterator[Node]:
        return iter(self.nodes)

    def __len__(self) -> int:
        return len(self.nodes)

    @property
    def timing(self) -> bool:
        """Whether ticks time every visit into their snapshots, for monitors.

        A visit's time covers the node and its subtree, breakpoint waits and other
        :attr:`Node.pre_tick <cyborg.bt.node.Node.pre_tick>` time left out. Off by default: it
        makes a tick three to four times as slow.

        Setting it takes effect when the next tick begins (never inside a tick); reading it
        gives the setting, and :attr:`TickSnapshot.timed
        <cyborg.bt.snapshot.TickSnapshot.timed>` whether a given tick was timed.
        """
        return self._timing_wanted

    @timing.setter
    def timing(self, on: bool) -> None:
        self._timing_wanted = bool(on)

    def _apply_timing(self) -> None:
        self._timing = on = self._timing_wanted
        for node in self.nodes:
            node.timed = on

    @property
    def running(self) -> list[Node]:
        """Nodes RUNNING after the last tick, deepest first."""
        return list(self._running)

    def tick(self) -> TickSnapshot:
        """Ticks the root once, halts what was abandoned, and returns the tick's snapshot."""
        if self._timing_wanted is not self._timing:
            self._apply_timing()
        record = self._record
        record.now = now = self.clock.now()
        visits: list[tuple[Node, Status]] = []
        running: list[Node] = []
        halted: list[Node] = []
        durations: dict[int, float] = {}
        record.visits, record.running, record.halted = visits, running, halted
        record.durations = durations
        started = perf_counter()
        services = self.services
        if services is not None:
            services.run_due(now)
        status = self.root.execute()
        previous = self._running
        if previous:
            still = set(running)
            for node in previous:  # deepest first, so children go before their parents
                if node.status is RUNNING and node not in still:
                    node.halt()
        if running:
            for node in running:
                parent = node.parent
                if parent is not None and parent.status is not RUNNING:
                    node.halt()  # left RUNNING under a parent that completed
            if halted:
                running = [node for node in running if node.status is RUNNING]
        self._running = running
        if services is not None:
            services.after_tick(running, halted, now)
        self.ticks = ticks = self.ticks + 1
        self.last = snapshot = TickSnapshot(
            ticks, now, perf_counter() - started, status, visits, running, halted, durations,
            None if services is None else services.states())
        return snapshot

    def halt(self) -> list[Node]:
        """Halts every RUNNING node, deepest first; returns the nodes halted."""
        record = self._record
        halted: list[Node] = []
        record.halted = halted
        self.root.halt()
        self._running = []
        if self.services is not None:
            self.services.stop_all(self.clock.now())
        return halted

    def missing_resources(self) -> dict[str, list[Node]]:
        """Resource key -> the nodes that need it but find none in the blackboard's resources.

        A node needs the keys of its :attr:`Node.requires <cyborg.bt.node.Node.requires>` and
        those its code fetches (:func:`~cyborg.bt.resources.requirements_of`), and a composite
        those of its services' ``requires``. The dict is empty when every node has
        what it needs.
        """
        missing: dict[str, list[Node]] = {}
        for node in self.nodes:
            for key in requirements_of(type(node)):
                if key not in self.blackboard.resources:
                    missing.setdefault(key, []).append(node)
        for scheduled in self.services.services if self.services is not None else ():
            for key in scheduled.service.requires:  # a service needs it: its composite does
                if key not in self.blackboard.resources and \
                        scheduled.composite not in missing.setdefault(key, []):
                    missing[key].append(scheduled.composite)
        return missing

    @property
    def structure(self) -> TreeStructure:
        """The tree's shape, for monitors and exports (built once)."""
        if self._structure is None:
            self._structure = TreeStructure.of(self)
        return self._structure

    def to_dot(self) -> str:
        """The structure as a Graphviz DOT graph."""
        from cyborg.bt.dot import structure_to_dot

        return structure_to_dot(self.structure.to_json())
