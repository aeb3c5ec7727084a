"""CPU cost of one behaviour-tree tick, per node visited: cyborg against py_trees 2.x.

Run from the repository root: ``python3 -m benchmarks.bt_tick`` (about 30 s); add
``--quick`` for a smoke test of a few seconds and ``--markdown`` for a Markdown table.

**Trees** (benchmarks/bt_tick_trees.py). Each shape is described once (:class:`Shape`) and
rendered three ways: a behavior3editor JSON export loaded with :func:`cyborg.bt.loads_tree`,
py_trees behaviours, and plain Python objects for the floor. Every leaf succeeds at once, so
every engine visits the same nodes each tick:

* ``wide`` -- 1,131 nodes, 5 levels: a root Sequence over 10 Priority nodes, each holding a
  Sequence of 10 Sequences of 10 leaves and then a fallback leaf. The first child of a Priority
  succeeds, so the 10 fallbacks are never reached: 1,121 nodes visited per tick.
* ``deep50`` -- 101 nodes, 51 levels: a chain of 50 composites alternating Sequence (its leaf,
  then the next composite) and Priority (the next composite, then its leaf, which is skipped);
  the last composite holds two leaves. 76 nodes visited per tick.
* ``deep10`` -- the same chain with 10 composites: 21 nodes, 11 levels, 16 visited.

cyborg wraps every loaded tree in a ``Subtree`` node (category ``tree``), so it has one node and
one visit more per tick. Each engine's cost is divided by its *own* visited count; both counts
are printed, and checked against the shape before anything is timed.

**Modes.** ``floor``: plain recursion, one method call per node appending it to a list.
``py_trees bare``: ``root.tick_once()``, recording nothing. ``py_trees + SnapshotVisitor``:
``BehaviourTree.tick()`` with py_trees' recorder of visited statuses. ``cyborg (snapshots
on)``: ``tree.tick()``, which returns a ``TickSnapshot`` every tick. ``cyborg + materialised
snapshot``: also reads the snapshot's ``visited`` and ``active`` lists (ids and statuses).
``cyborg + idle services``: ``tree.tick()`` with a service of a 1 h interval declared on every
composite (``services = "Idle(interval=3600)"``), attached and idle; the goal holds for it too.

**Timing.** A batch of ticks is timed with ``time.thread_time_ns`` (this thread's CPU time
only) with the garbage collector off; batches are sized to about 0.2 s (5 ms with
``--quick``), repeats go round-robin over the modes so a slow spell hits every mode alike, and
the median repeat is reported. The loop's one call per tick is included, not subtracted.
"""

from __future__ import annotations

import argparse
import gc
import os
import platform
import statistics
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import partial
from importlib.metadata import version

import py_trees

from benchmarks import benchmark_options
from benchmarks.bt_tick_trees import (
    SHAPES,
    FloorNode,
    Shape,
    to_behavior3_json,
    to_floor,
    to_py_trees,
)
from cyborg.bt import ManualClock, Service, ServiceBoard, ServiceRegistry, loads_tree
from cyborg.bt.registry import default_registry

SPEED_UP_GOAL = 15.0
"""cyborg with snapshots on should cost at most 1/15 of py_trees' bare tick per node."""

# ---------------------------------------------------------------------------- modes
@dataclass(frozen=True)
class Ticker:
    """A ready-to-tick tree in one mode, with what one tick of it visits."""

    tick: Callable[[], object]
    nodes: int
    """Nodes in the tree, by the engine's own count."""
    visited: int
    """Nodes visited per tick, by the engine's own count."""


def floor_ticker(shape: Shape) -> Ticker:
    root = to_floor(shape)

    def tick() -> list[FloorNode]:
        visited: list[FloorNode] = []
        root.run(visited)
        return visited

    return Ticker(tick, shape.node_count, len(tick()))


def py_trees_bare_ticker(shape: Shape) -> Ticker:
    root = to_py_trees(shape)
    root.tick_once()  # the first tick initialises every behaviour
    visited = sum(1 for _ in root.tick())
    return Ticker(root.tick_once, sum(1 for _ in root.iterate()), visited)


def py_trees_snapshot_ticker(shape: Shape) -> Ticker:
    tree = py_trees.trees.BehaviourTree(to_py_trees(shape))
    visitor = py_trees.visitors.SnapshotVisitor()
    tree.add_visitor(visitor)
    tree.tick()
    tree.tick()
    return Ticker(tree.tick, sum(1 for _ in tree.root.iterate()), len(visitor.visited))


class Idle(Service):
    """A service with nothing to do, for the idle-services mode."""

    def run(self, blackboard: ServiceBoard) -> None:
        """Nothing: the mode measures what attached services cost the tick."""


def cyborg_ticker(shape: Shape, *, materialise: bool, services: str = "") -> Ticker:
    """``tree.tick()``; with ``materialise``, also the snapshot's id and status lists."""
    registry = ServiceRegistry()
    registry.add(Idle)
    tree = loads_tree(to_behavior3_json(shape, "bench", services), clock=ManualClock(),
                      services=registry, registry=default_registry(entry_points=False))
    if services and (tree.services is None or len(tree.services.services) < 2):
        raise RuntimeError("the idle services were not attached")

    def tick_and_read() -> tuple[object, object]:
        snapshot = tree.tick()
        return snapshot.visited, snapshot.active

    tick = tick_and_read if materialise else tree.tick
    tick()
    return Ticker(tick, len(tree), len(tree.tick().visited))


FLOOR = "floor"
PY_TREES_BARE = "py_trees bare"
CYBORG = "cyborg (snapshots on)"
CYBORG_IDLE_SERVICES = "cyborg + idle services"
MODES: dict[str, Callable[[Shape], Ticker]] = {
    FLOOR: floor_ticker,
    PY_TREES_BARE: py_trees_bare_ticker,
    "py_trees + SnapshotVisitor": py_trees_snapshot_ticker,
    CYBORG: partial(cyborg_ticker, materialise=False),
    "cyborg + materialised snapshot": partial(cyborg_ticker, materialise=True),
    CYBORG_IDLE_SERVICES: partial(cyborg_ticker, materialise=False,
                                  services="Idle(interval=3600)"),
}
CYBORG_WRAPPER_NODES = 1
"""The ``Subtree`` node cyborg puts above every loaded tree's root."""


def prepare(shape: Shape) -> dict[str, Ticker]:
    """Build the shape in every mode and check that all engines visit the same nodes."""
    tickers = {mode: build(shape) for mode, build in MODES.items()}
    for mode, ticker in tickers.items():
        extra = CYBORG_WRAPPER_NODES if mode.startswith("cyborg") else 0
        expected = (shape.node_count + extra, shape.visits_per_tick + extra)
        if (ticker.nodes, ticker.visited) != expected:
            raise RuntimeError(f"{mode}: (nodes, visited per tick) is "
                               f"{(ticker.nodes, ticker.visited)}, expected {expected}")
    return tickers


# ---------------------------------------------------------------------------- timing
def time_batch(tick: Callable[[], object], ticks: int) -> int:
    """Thread CPU time, in ns, of ``ticks`` calls to ``tick`` with the collector off."""
    gc.collect()
    gc.disable()
    try:
        started = time.thread_time_ns()
        for _ in range(ticks):
            tick()
        return time.thread_time_ns() - started
    finally:
        gc.enable()


def calibrate(tick: Callable[[], object], target_ns: int) -> int:
    """How many ticks make a batch of about ``target_ns``."""
    ticks = 1
    while True:
        elapsed = time_batch(tick, ticks)
        if elapsed >= target_ns // 20:
            return max(1, round(ticks * target_ns / max(elapsed, 1)))
        ticks *= 4


@dataclass(frozen=True)
class Measurement:
    """The median cost of one tick of one tree in one mode."""

    tree: str
    mode: str
    nodes: int
    visited: int
    ns_per_tick: float
    spread: float
    """(slowest - fastest repeat) / median, as a fraction."""

    @property
    def ns_per_node(self) -> float:
        return self.ns_per_tick / self.visited


def measure(tree: str, tickers: dict[str, Ticker], repeats: int,
            target_ns: int) -> list[Measurement]:
    """Median ns per tick of each mode, repeats taken round-robin over the modes."""
    batch = {mode: calibrate(ticker.tick, target_ns) for mode, ticker in tickers.items()}
    samples: dict[str, list[float]] = {mode: [] for mode in tickers}
    for _ in range(repeats):
        for mode, ticker in tickers.items():
            samples[mode].append(time_batch(ticker.tick, batch[mode]) / batch[mode])
    results = []
    for mode, ticker in tickers.items():
        median = statistics.median(samples[mode])
        spread = (max(samples[mode]) - min(samples[mode])) / median
        results.append(Measurement(tree, mode, ticker.nodes, ticker.visited, median, spread))
    return results


# ---------------------------------------------------------------------------- report
HEADERS = ("tree", "mode", "nodes", "visited/tick", "ns/tick", "ns/visited node",
           "speed-up vs py_trees bare", "cost / floor", "spread")


def table_rows(results: Sequence[Measurement]) -> list[tuple[str, ...]]:
    """One row per measurement; ratios compare per-node costs within the same tree."""
    by_key = {(m.tree, m.mode): m for m in results}
    rows: list[tuple[str, ...]] = []
    for m in results:
        py_trees_bare = by_key[(m.tree, PY_TREES_BARE)].ns_per_node
        floor = by_key[(m.tree, FLOOR)].ns_per_node
        rows.append((m.tree, m.mode, f"{m.nodes:,}", f"{m.visited:,}", f"{m.ns_per_tick:,.0f}",
                     f"{m.ns_per_node:,.1f}", f"{py_trees_bare / m.ns_per_node:.1f}x",
                     f"{m.ns_per_node / floor:.1f}x", f"{m.spread:.0%}"))
    return rows


def render_text(rows: list[tuple[str, ...]]) -> str:
    widths = [max(len(row[i]) for row in [HEADERS, *rows]) for i in range(len(HEADERS))]
    numeric = range(2, len(HEADERS))

    def line(row: tuple[str, ...]) -> str:
        cells = (cell.rjust(w) if i in numeric else cell.ljust(w)
                 for i, (cell, w) in enumerate(zip(row, widths, strict=True)))
        return "  ".join(cells).rstrip()

    rule = "  ".join("-" * w for w in widths)
    return "\n".join([line(HEADERS), rule, *(line(row) for row in rows)])


def render_markdown(rows: list[tuple[str, ...]]) -> str:
    align = ["---", "---", *["--:"] * (len(HEADERS) - 2)]
    lines = [HEADERS, tuple(align), *rows]
    return "\n".join("| " + " | ".join(row) + " |" for row in lines)


def machine_description() -> list[str]:
    return [
        f"Python {platform.python_version()} ({platform.python_implementation()}), "
        f"{platform.platform()}, {platform.machine()}, {os.cpu_count()} CPUs",
        f"cyborg {version('cyborg')}, py_trees {py_trees.version.__version__}",
    ]


def headline(results: Sequence[Measurement]) -> list[str]:
    """Per tree: how many times cheaper per node cyborg with snapshots is than bare py_trees."""
    by_key = {(m.tree, m.mode): m for m in results}
    lines = []
    for tree in dict.fromkeys(m.tree for m in results):
        for mode, what in ((CYBORG, "with snapshots"), (CYBORG_IDLE_SERVICES,
                                                         "with idle services attached")):
            speed_up = by_key[(tree, PY_TREES_BARE)].ns_per_node / by_key[(tree, mode)].ns_per_node
            verdict = "meets" if speed_up >= SPEED_UP_GOAL else "MISSES"
            lines.append(f"{tree}: cyborg {what} is {speed_up:.1f}x faster per visited node "
                         f"than bare py_trees ({verdict} the {SPEED_UP_GOAL:.0f}x goal)")
    return lines


def parser() -> argparse.ArgumentParser:
    """The benchmark's options."""
    return benchmark_options(__doc__, quick="batches of 5 ms, 2 repeats")


def main(argv: Sequence[str] | None = None) -> int:
    arguments = parser().parse_args(argv)
    repeats = 2 if arguments.quick else 7
    target_ns = 5_000_000 if arguments.quick else 200_000_000
    prefix = "- " if arguments.markdown else ""
    for line in machine_description():
        print(prefix + line)
    print(f"{prefix}timer: time.thread_time_ns, median of {repeats} batches of "
          f"~{target_ns / 1e9:.2f} s each, gc disabled while timing")
    print()

    results: list[Measurement] = []
    for name, make_shape in SHAPES.items():
        shape = make_shape()
        tickers = prepare(shape)
        gc.freeze()  # the trees are built: each batch's collection need not walk them again
        cyborg = tickers[CYBORG]
        print(f"{prefix}{name}: depth {shape.depth}; nodes {shape.node_count:,} (cyborg "
              f"{cyborg.nodes:,}); visited per tick {shape.visits_per_tick:,} (cyborg "
              f"{cyborg.visited:,}, including its Subtree wrapper)", flush=True)
        results.extend(measure(name, tickers, repeats, target_ns))

    rows = table_rows(results)
    print()
    print(render_markdown(rows) if arguments.markdown else render_text(rows))
    print()
    for line in headline(results):
        print(prefix + line)
    return 0


if __name__ == "__main__":
    sys.exit(main())
