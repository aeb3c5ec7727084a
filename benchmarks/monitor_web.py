"""Web monitor: tick -> browser latency at 20 Hz, and first paint of a 1,000-node tree.

    python3 -m benchmarks.monitor_web              # about a minute
    python3 -m benchmarks.monitor_web --quick      # a few seconds per part
    python3 -m benchmarks.monitor_web --markdown   # the table for docs/benchmarks.md

A random behaviour tree of 1,000 nodes (composites of 2-6 children, as in the monitor
reference; Wait leaves of 100-400 ms keep statuses changing) is ticked at 20 Hz by a tree runner
on an isolated bus; a monitor serves it; headless Chromium (Debian's) shows it.

* **Latency** is measured from the start of a tick (wall clock) to the animation frame in which
  the page has painted that tick. The named baseline, measured in the same run, is the
  **transport floor**: a plain Python WebSocket client receiving the same frames (no browser,
  no drawing). Goal: p50 <= 30 ms.
* **First paint** is the time from navigation start to the first animation frame with the tree
  drawn as the page shows it by default (page, modules, WebSocket, structure, layout, SVG: at its
  readable size, deep subtrees folded to fit the view, so a few dozen of the nodes). The named
  baseline is **Graphviz** (`dot -Tsvg`, what rqt_bt laid its trees out with) on the same tree, in
  the same run. Goal: <= 300 ms.
"""

from __future__ import annotations

import argparse
import json
import random
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

from playwright.sync_api import sync_playwright
from websockets.sync.client import connect

from benchmarks import benchmark_options
from benchmarks.results_table import print_results
from cyborg.bt.dot import structure_to_dot
from cyborg.bus import BusConfig, Context, Node
from cyborg.monitor import Monitor
from cyborg.runner.tree_runner import TreeRunnerNode

NODES = 1000
RATE_HZ = 20.0
LATENCY_GOAL_MS = 30.0
FIRST_PAINT_GOAL_MS = 300.0
COMPOSITES = ("Sequence", "Priority", "MemSequence", "MemPriority")


def random_tree(count: int, seed: int = 7) -> str:
    """A behavior3editor export: Repeater(-1) over a random tree of about ``count`` nodes."""
    rng = random.Random(seed)
    nodes: dict[str, dict[str, Any]] = {}

    def add(name: str, properties: dict[str, Any] | None = None) -> dict[str, Any]:
        node_id = f"n{len(nodes)}"
        title = f"{name} {len(nodes)}"
        if name == "Wait":
            title = f"Wait {properties['milliseconds'] if properties else 0}ms"
        node = {"id": node_id, "name": name, "title": title, "description": "",
                "properties": properties or {}}
        nodes[node_id] = node
        return node

    root = add("Repeater", {"maxLoop": -1})
    top = add("MemSequence")
    root["child"] = top["id"]
    frontier = [top]
    budget = count - 2
    while frontier and budget > 0:
        parent = frontier.pop(0)
        children = []
        for position in range(rng.randint(2, 6)):
            if budget <= 0:
                break
            budget -= 1
            grow = not frontier and position == 0  # keep the tree growing
            if (grow or rng.random() < 0.3) and budget > 6:
                child = add(rng.choice(COMPOSITES))
                frontier.append(child)
            else:
                child = add("Wait", {"milliseconds": rng.randrange(100, 400, 50)})
            children.append(child["id"])
        parent["children"] = children
    for leftover in frontier:
        leftover["children"] = [add("Succeeder")["id"]]
    return json.dumps({"version": "0.3.0", "scope": "tree", "id": "bench", "title": "bench",
                       "description": "", "root": root["id"], "properties": {},
                       "nodes": nodes})


def percentile(values: list[float], fraction: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, round(fraction * (len(ordered) - 1)))]


class TickClock:
    """Wall-clock start of every tick, by tick number."""

    def __init__(self, runner: TreeRunnerNode) -> None:
        self.starts: dict[int, float] = {}
        runner.runner.add_listener(self._on_tick)

    def _on_tick(self, snapshot: Any) -> None:
        self.starts[snapshot.tick] = time.time() - (time.monotonic() - snapshot.time)


def floor_latency(url: str, ticks: TickClock, seconds: float) -> list[float]:
    """Tick -> arrival at a plain WebSocket client, in ms."""
    latencies: list[float] = []
    with connect(url.replace("http", "ws") + "ws") as socket:
        socket.send(json.dumps({"t": "hello", "key": "floor"}))
        socket.send(json.dumps({"t": "watch", "ns": "/bench/bt"}))
        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline:
            message = json.loads(socket.recv(timeout=5))
            arrived = time.time()
            if message["t"] == "tick" and message["tick"] in ticks.starts:
                latencies.append((arrived - ticks.starts[message["tick"]]) * 1000.0)
    return latencies


def browser_latency(page: Any, ticks: TickClock, seconds: float) -> tuple[list[float], int]:
    """Tick -> painted in the page, in ms; and how many ticks were merged into later frames."""
    page.evaluate("window.__monitor.paints = []; window.__monitor.recordPaints = true")
    time.sleep(seconds)
    paints = page.evaluate("window.__monitor.recordPaints = false; window.__monitor.paints")
    latencies, seen = [], set()
    for tick, painted_ms in paints:
        if tick in seen or tick not in ticks.starts:
            continue
        seen.add(tick)
        latencies.append(painted_ms - ticks.starts[tick] * 1000.0)
    first, last = min(seen), max(seen)
    return latencies, (last - first + 1) - len(seen)


def first_paints(browser: Any, url: str, runs: int) -> tuple[list[float], list[float]]:
    """Navigation start -> tree painted as shown by default, and the page's own layout+DOM time,
    in ms."""
    totals, draws = [], []
    for _ in range(runs):
        page = browser.new_page(viewport={"width": 1400, "height": 820})
        page.goto(url)
        page.wait_for_function("window.__monitor && window.__monitor.firstPaint !== null",
                               timeout=30000)
        total = page.evaluate("window.__monitor.firstPaint - performance.timeOrigin")
        totals.append(total)
        draws.append(page.evaluate("window.__monitor.drawMs"))
        page.close()
    return totals, draws


def graphviz_layout(structure: dict[str, Any], runs: int) -> list[float]:
    dot = shutil.which("dot")
    if dot is None:
        raise SystemExit("Graphviz 'dot' is needed for the baseline (apt install graphviz)")
    text = structure_to_dot(structure)
    times = []
    for _ in range(runs):
        started = time.perf_counter()
        subprocess.run([dot, "-Tsvg"], input=text.encode(), capture_output=True, check=True)
        times.append((time.perf_counter() - started) * 1000.0)
    return times


def parser() -> argparse.ArgumentParser:
    """The benchmark's options."""
    return benchmark_options(__doc__, quick="1.5 s of ticks, one page load")


def main(argv: list[str] | None = None) -> int:
    args = parser().parse_args(argv)
    seconds, runs = (1.5, 1) if args.quick else (15.0, 5)
    chromium = shutil.which("chromium")
    if chromium is None:
        raise SystemExit("Debian's chromium is needed (apt install chromium)")
    with tempfile.TemporaryDirectory() as folder, Context(BusConfig.isolated()) as context:
        path = Path(folder) / "bench.b3.json"
        path.write_text(random_tree(NODES))
        runner = TreeRunnerNode(Node("tree_runner", "/bench/bt", context=context), path,
                                rate_hz=RATE_HZ)
        monitor = Monitor(Node("monitor", "/bench", context=context), namespaces=["/bench/bt"],
                          host="127.0.0.1", port=0)
        ticks = TickClock(runner)
        runner.start()
        monitor.start()
        url = monitor.urls()[0]
        nodes = len(runner.tree)
        try:
            floor = floor_latency(url, ticks, seconds)
            with sync_playwright() as playwright:
                browser = playwright.chromium.launch(executable_path=chromium,
                                                     args=["--disable-gpu", "--disable-quic"])
                totals, draws = first_paints(browser, url, runs)
                page = browser.new_page(viewport={"width": 1400, "height": 820})
                page.goto(url)
                page.wait_for_function("window.__monitor && window.__monitor.frames > 5",
                                       timeout=30000)
                ours, merged = browser_latency(page, ticks, seconds)
                browser.close()
            layout = graphviz_layout(runner.tree.structure.to_json(), max(2, runs // 2))
        finally:
            monitor.stop()
            runner.destroy()
    report(nodes, floor, ours, merged, totals, draws, layout, args.markdown)
    ok = statistics.median(ours) <= LATENCY_GOAL_MS and \
        statistics.median(totals) <= FIRST_PAINT_GOAL_MS
    return 0 if ok or args.quick else 1


def report(nodes: int, floor: list[float], ours: list[float], merged: int,
           totals: list[float], draws: list[float], layout: list[float], markdown: bool) -> None:
    floor50, ours50 = statistics.median(floor), statistics.median(ours)
    paint50, layout50 = statistics.median(totals), statistics.median(layout)
    rows = [
        ("tick -> painted in Chromium (p50 / p95)",
         f"{ours50:.1f} / {percentile(ours, .95):.1f} ms",
         f"{ours50 / floor50:.1f}x the floor", f"p50 <= {LATENCY_GOAL_MS:g} ms"),
        ("transport floor: tick -> Python WebSocket client (p50 / p95)",
         f"{floor50:.1f} / {percentile(floor, .95):.1f} ms", "baseline", ""),
        ("first paint, navigation -> tree drawn as shown (median)", f"{paint50:.0f} ms",
         f"{paint50 / layout50:.2f}x Graphviz", f"<= {FIRST_PAINT_GOAL_MS:g} ms"),
        ("  of which layout + SVG in the page (median)", f"{statistics.median(draws):.0f} ms",
         "", ""),
        ("Graphviz `dot -Tsvg` layout of the same tree (median)", f"{layout50:.0f} ms",
         "baseline", ""),
    ]
    header = (f"{nodes}-node tree ticked at {RATE_HZ:g} Hz; {len(ours)} ticks painted "
              f"({merged} merged into a later frame), {len(floor)} received by the floor client")
    print_results(header, rows, markdown=markdown, widths=(62, 16, 18))
    def verdict(ok: bool) -> str:
        return "meets" if ok else "MISSES"
    verdicts = [f"latency p50 {ours50:.1f} ms ({verdict(ours50 <= LATENCY_GOAL_MS)}"
                f" the {LATENCY_GOAL_MS:g} ms goal)",
                f"first paint {paint50:.0f} ms ({verdict(paint50 <= FIRST_PAINT_GOAL_MS)}"
                f" the {FIRST_PAINT_GOAL_MS:g} ms goal)"]
    print("\n" + "; ".join(verdicts), file=sys.stderr if not markdown else sys.stdout)


if __name__ == "__main__":
    raise SystemExit(main())
