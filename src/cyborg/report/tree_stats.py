"""What each node of a recorded tree did: status counts, running time and tick time.

From the tree runner's ``behavior_tree`` structure (read as a :class:`~cyborg.bt.outline.
StructureOutline`) and its per-tick ``status`` messages, as the monitor reads them live, this
counts for every node:

* how many ticks it returned success, failure, running and error in;
* its *running time*: for every tick it returned running, the tree-clock time until the next
  tick (the tree's own clock: simulated time under a simulator), summed;
* its *tick time*: the wall time its visits took (``visited_durations``, subtree included),
  summed, and the visits that were timed.

A runner that reloads its tree publishes a new structure: each becomes a :class:`TreeRun` of
its own, fed the ticks that came after it. Ticks recorded before any structure are counted in
:attr:`TreeHistory.orphan_ticks`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from cyborg.bt.outline import StructureError, StructureOutline
from cyborg.bt.status import Status
from cyborg.report.recording import Stamped

STATUSES: tuple[Status, ...] = (Status.SUCCESS, Status.FAILURE, Status.RUNNING, Status.ERROR)
"""The statuses counted per node, in the report's column order."""


@dataclass
class NodeStats:
    """What one node did over a tree run."""

    counts: dict[Status, int] = field(default_factory=lambda: dict.fromkeys(STATUSES, 0))
    running_time: float = 0.0
    """Seconds of the tree's clock spent running (see the module)."""
    tick_time: float = 0.0
    """Wall seconds its timed visits took, subtree included."""
    timed: int = 0
    """Visits whose time was measured."""

    @property
    def visits(self) -> int:
        """Ticks the node was visited in."""
        return sum(self.counts.values())


@dataclass
class TreeRun:
    """One structure of a tree and what its nodes did until the next one came."""

    outline: StructureOutline
    received: int
    """Log time of the structure message (ns)."""
    nodes: list[NodeStats] = field(default_factory=list)
    ticks: int = 0
    first_tick: int = 0
    last_tick: int = 0
    root_counts: dict[Status, int] = field(default_factory=lambda: dict.fromkeys(STATUSES, 0))
    failures: list[tuple[int, int, int]] = field(default_factory=list)
    """Runs of consecutive ticks whose root failed: (log time, first tick, last tick)."""
    errors: list[tuple[int, int, str]] = field(default_factory=list)
    """Nodes that returned error: (log time, tick, label), the first of each run."""

    def __post_init__(self) -> None:
        self.nodes = [NodeStats() for _ in range(len(self.outline))]

    @property
    def title(self) -> str:
        """The tree's title, or its source file, from the structure."""
        structure = self.outline.structure
        return str(structure.get("title") or structure.get("source") or "tree")


@dataclass
class TreeHistory:
    """Every structure a tree runner published in a recording, with its ticks."""

    runs: list[TreeRun] = field(default_factory=list)
    orphan_ticks: int = 0
    """Ticks recorded before any structure (they name nodes of no known tree)."""
    problems: list[str] = field(default_factory=list)
    """Structures that could not be read."""


def tree_history(structures: list[Stamped], statuses: list[Stamped]) -> TreeHistory:
    """Replays the structure and status messages of one runner in log-time order."""
    history = TreeHistory()
    events = sorted([(item.log_time, 0, item.message) for item in structures]
                    + [(item.log_time, 1, item.message) for item in statuses],
                    key=lambda event: (event[0], event[1]))
    pending: tuple[TreeRun, int, float, list[int]] | None = None  # the last tick's running nodes
    last_failed: int | None = None
    erring: set[int] = set()
    for log_time, kind, message in events:
        if kind == 0:
            try:
                outline = StructureOutline.parse(str(message.tree))
            except StructureError as exc:
                history.problems.append(str(exc))
                continue
            if history.runs and history.runs[-1].outline.structure == outline.structure:
                continue  # the same tree again (a latched message received twice)
            history.runs.append(TreeRun(outline, log_time))
            pending, last_failed, erring = None, None, set()
            continue
        if not history.runs:
            history.orphan_ticks += 1
            continue
        run = history.runs[-1]
        tick, time = int(message.tick), _seconds(message.stamp)
        if pending is not None and pending[0] is run:
            elapsed = max(0.0, time - pending[2])
            for index in pending[3]:
                run.nodes[index].running_time += elapsed
        running, erring = _apply(run, message, log_time, tick, erring)
        pending = (run, tick, time, running)
        root = _status(int(message.status))
        if root is not None:
            run.root_counts[root] += 1
        if root is Status.FAILURE:
            if last_failed is not None and run.failures and run.failures[-1][2] == last_failed:
                first_time, first, _ = run.failures[-1]
                run.failures[-1] = (first_time, first, tick)
            else:
                run.failures.append((log_time, tick, tick))
            last_failed = tick
        run.ticks += 1
        run.first_tick = run.first_tick or tick
        run.last_tick = tick
    return history


def _apply(run: TreeRun, message: Any, log_time: int, tick: int,
           erring: set[int]) -> tuple[list[int], set[int]]:
    """Counts one tick's visits; returns the nodes left running and those that erred."""
    index_of = run.outline.index_of
    statuses = list(message.visited_statuses)
    durations = list(message.visited_durations)
    timed = len(durations) == len(message.visited_ids)
    running: list[int] = []
    erred: set[int] = set()
    for position, uid in enumerate(message.visited_ids):
        index = index_of.get(str(uid))
        status = _status(int(statuses[position])) if position < len(statuses) else None
        if index is None or status is None:
            continue
        node = run.nodes[index]
        node.counts[status] += 1
        if status is Status.RUNNING:
            running.append(index)
        elif status is Status.ERROR:
            erred.add(index)
            if index not in erring:
                run.errors.append((log_time, tick, run.outline.labels[index]))
        if timed and not math.isnan(float(durations[position])):
            node.tick_time += float(durations[position])
            node.timed += 1
    return running, erred


def _status(code: int) -> Status | None:
    try:
        return Status(code)
    except ValueError:
        return None


def _seconds(stamp: Any) -> float:
    return float(stamp.sec) + float(stamp.nanosec) * 1e-9
