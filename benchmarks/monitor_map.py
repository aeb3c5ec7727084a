"""Map view: three robots at 10 Hz on columbia.map, pose to painted frame in Chromium.

    python3 -m benchmarks.monitor_map              # about a minute
    python3 -m benchmarks.monitor_map --quick      # a few seconds per part
    python3 -m benchmarks.monitor_map --markdown   # the table for docs/benchmarks.md

Three stand-in robots (``/robot1`` .. ``/robot3``) publish on an isolated bus what the
simulator publishes for the map: ``map_geometry`` of columbia.map (the largest public ARNL
map: 63,311 points) latched, the footprint and ``/tf_static`` latched, a path and its state,
the battery once a second, and at 10 Hz each a pose and a 541-beam scan (in the simulator's
order: pose, then scan), each robot driving round a circle. A tree runner ticks a random
100-node tree at 10 Hz under ``/robot1/bt``, so the page shows a tree beside the map, as under
``cyborg up``. A monitor follows them all; headless Chromium (Debian's) shows the page at
1000 x 600.

* **Pose -> painted**: from the wall-clock moment a pose is published to the moment the page
  has rendered the frame that first draws it (a task queued from the next animation frame,
  ``window.__map.paintTimes``). Poses are matched by value: the publisher keeps when it sent
  each (whole millimetres, so the monitor's rounding keeps them exact), a plain WebSocket
  client beside the page hears which ``rs`` (robot, ``seq``) carried which pose, and the page
  records the ``seq`` of every robot at every frame. The named baseline, same run: the
  **transport floor**, that plain client's arrival time of the same ``rs`` messages. Goals:
  p50 <= 50 ms, p99 <= 150 ms.
* **First paint of the map**: navigation start to the first rendered frame with columbia
  drawn (``window.__map.firstPaint``), fresh browser contexts (cold caches); the baseline is the
  **tree's first paint** in the same loads (the map's code loads after it). Goal: <= 1 s.
* **Main-thread time per second** (Chrome DevTools Protocol ``Performance.getMetrics``,
  ``TaskDuration`` and ``ScriptDuration`` deltas over a window) with the map showing the three
  robots, against the **tree view alone** (the tree maximised: the page does not ask for map
  data), windows of each alternated on one page, medians.
"""

from __future__ import annotations

import argparse
import json
import math
import shutil
import statistics
import sys
import tempfile
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from playwright.sync_api import Browser, Page, ViewportSize, sync_playwright
from websockets.sync.client import connect

from benchmarks import SHARED, benchmark_options
from benchmarks.monitor_web import percentile, random_tree
from benchmarks.results_table import print_results
from cyborg.bus import BusConfig, Context, Node
from cyborg.bus.msgs.builtin_interfaces.msg import Time
from cyborg.bus.msgs.cyborg_msgs.msg import BatteryStatus
from cyborg.bus.msgs.geometry_msgs.msg import (
    Point32,
    Polygon,
    PolygonStamped,
    Quaternion,
    Transform,
    TransformStamped,
    Vector3,
)
from cyborg.bus.msgs.sensor_msgs.msg import LaserScan
from cyborg.bus.msgs.std_msgs.msg import Header, String
from cyborg.bus.msgs.tf2_msgs.msg import TFMessage
from cyborg.interfaces import robot
from cyborg.monitor import Monitor
from cyborg.nav.arnl_map import read_map
from cyborg.nav.geometry import Path as NavPath
from cyborg.nav.geometry import Pose2D
from cyborg.nav.map_message import map_geometry
from cyborg.runner.tree_runner import TreeRunnerNode

MAP = SHARED / "maps" / "columbia.map"
ROBOTS = ("/robot1", "/robot2", "/robot3")
RATE_HZ = 10.0
BEAMS = 541
TREE_NODES = 100
VIEWPORT: ViewportSize = {"width": 1000, "height": 600}
P50_GOAL_MS, P99_GOAL_MS, FIRST_PAINT_GOAL_MS = 50.0, 150.0, 1000.0
CENTRES = ((-0.5, 0.8), (5.0, 0.0), (-3.2, 4.8))
"""Where each robot's circle is: columbia's corridors near its home."""
RADIUS = 2.0


def stamp_now() -> Time:
    sec, nanosec = divmod(time.time_ns(), 1_000_000_000)
    return Time(sec=sec, nanosec=nanosec)


@dataclass
class Published:
    """When each pose was published (wall clock, s), by robot and whole millimetres."""

    at: dict[tuple[str, int, int], float] = field(default_factory=dict)
    lock: threading.Lock = field(default_factory=threading.Lock)

    def note(self, ns: str, x: float, y: float) -> None:
        with self.lock:
            self.at[(ns, round(x * 1000), round(y * 1000))] = time.time()

    def when(self, ns: str, x: float, y: float) -> float | None:
        with self.lock:
            return self.at.get((ns, round(x * 1000), round(y * 1000)))


class StandInRobots:
    """Three robots' map topics on ``context``, as the simulator publishes them."""

    def __init__(self, context: Context, published: Published) -> None:
        self.published = published
        self.nodes = [Node("arnl", ns, context=context) for ns in ROBOTS]
        geometry = map_geometry(read_map(MAP), stamp_now())
        self.points = len(geometry.points) // 2
        self.pose = [robot.POSE.publisher(node) for node in self.nodes]
        self.scan = [robot.SCAN.publisher(node) for node in self.nodes]
        self.battery = [robot.BATTERY_STATUS.publisher(node) for node in self.nodes]
        self._latched: list[Any] = []  # keeps the latched publishers alive
        for index, node in enumerate(self.nodes):
            latched: list[tuple[Any, Any]] = [
                (robot.MAP_GEOMETRY, geometry), (robot.FOOTPRINT, footprint()),
                (robot.TF_STATIC, transforms()),
                (robot.PATH, circle_path(index).to_message(stamp=stamp_now())),
                (robot.PATH_STATE, String(data="MOVING_TO_GOAL"))]
            for topic, message in latched:
                publisher = topic.publisher(node)
                publisher.publish(message)
                self._latched.append(publisher)
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self._run, name="stand-in robots", daemon=True)

    def start(self) -> None:
        self.thread.start()

    def _run(self) -> None:
        step = 0
        period = 1.0 / RATE_HZ
        next_at = time.monotonic()
        while not self.stop.is_set():
            for index, ns in enumerate(ROBOTS):
                pose = circle_pose(index, step)
                self.published.note(ns, pose.x, pose.y)
                self.pose[index].publish(pose.to_message())
                self.scan[index].publish(scan(step + 17 * index))
                if step % int(RATE_HZ) == 0:
                    self.battery[index].publish(battery(step, index))
            step += 1
            next_at += period
            self.stop.wait(max(0.0, next_at - time.monotonic()))

    def destroy(self) -> None:
        self.stop.set()
        self.thread.join(5)
        for node in self.nodes:
            node.destroy()


def circle_pose(index: int, step: int) -> Pose2D:
    """Robot ``index`` at ``step``: round its circle, 0.3 m/s, in whole millimetres."""
    angle = step * 0.3 / RATE_HZ / RADIUS + index * 2.1
    cx, cy = CENTRES[index]
    return Pose2D(round(cx + RADIUS * math.cos(angle), 3), round(cy + RADIUS * math.sin(angle), 3),
                  math.remainder(angle + math.pi / 2, 2 * math.pi))


def circle_path(index: int) -> NavPath:
    return NavPath.through(circle_pose(index, step) for step in range(0, 420, 10))


def scan(step: int) -> LaserScan:
    """A 270-degree, 541-beam scan whose ranges change every time, a few beams with no return."""
    beams = np.arange(BEAMS)
    ranges = (3.0 + 1.5 * np.sin(beams / 23 + step / 7)).astype(np.float32)
    ranges[::97] = np.inf
    increment = 1.5 * math.pi / (BEAMS - 1)
    return LaserScan(header=Header(stamp=stamp_now(), frame_id=robot.LASER_FRAME),
                     angle_min=-0.75 * math.pi, angle_max=0.75 * math.pi,
                     angle_increment=increment, time_increment=0.0, scan_time=0.1,
                     range_min=0.02, range_max=30.0, ranges=ranges,
                     intensities=np.zeros(0, np.float32))


def battery(step: int, index: int) -> BatteryStatus:
    return BatteryStatus(header=Header(stamp=stamp_now(), frame_id=robot.BASE_FRAME),
                         charging_state=BatteryStatus.CHARGING_NOT,
                         charge_percent=90.0 - 10 * index - step / 600, voltage=25.0,
                         charging=False, dock_state=BatteryStatus.DOCK_UNDOCKED)


def footprint() -> PolygonStamped:
    """The Pioneer LX's outline, roughly (the page draws whatever comes)."""
    corners = [(0.35, 0.25), (-0.35, 0.25), (-0.35, -0.25), (0.35, -0.25)]
    return PolygonStamped(header=Header(stamp=stamp_now(), frame_id=robot.BASE_FRAME),
                          polygon=Polygon(points=[Point32(x=x, y=y, z=0.0) for x, y in corners]))


def transforms() -> TFMessage:
    mount = TransformStamped(
        header=Header(stamp=stamp_now(), frame_id=robot.BASE_FRAME),
        child_frame_id=robot.LASER_FRAME,
        transform=Transform(translation=Vector3(x=0.267, y=0.0, z=0.0),
                            rotation=Quaternion(x=0.0, y=0.0, z=0.0, w=1.0)))
    return TFMessage(transforms=[mount])


# ---------------------------------------------------------------------- the floor client
class FloorClient:
    """A plain WebSocket client that opts in to the map, as a page does, and notes every ``rs``:
    which pose each (robot, seq) carried and when it arrived (wall clock, s)."""

    def __init__(self, url: str) -> None:
        self.url = url.replace("http", "ws") + "ws"
        self.received: dict[tuple[str, int], tuple[float, float, float]] = {}
        self.rs_messages = 0
        self.scans = 0
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self._run, name="floor client", daemon=True)

    def start(self) -> None:
        self.thread.start()

    def _run(self) -> None:
        with connect(self.url) as socket:
            socket.send(json.dumps({"t": "hello", "key": "floor"}))
            socket.send(json.dumps({"t": "watch", "ns": "/robot1/bt"}))
            socket.send(json.dumps({"t": "map", "on": True}))
            while not self.stop.is_set():
                try:
                    text = socket.recv(timeout=1)
                except TimeoutError:
                    continue
                arrived = time.time()
                message = json.loads(text)
                if message.get("t") != "rs":
                    continue
                self.rs_messages += 1
                self.scans += "sc" in message
                x, y, _theta = message["p"]
                self.received.setdefault((message["ns"], message["seq"]), (x, y, arrived))

    def robots_seen(self) -> set[str]:
        return {ns for ns, _seq in list(self.received)}


# ---------------------------------------------------------------------- in the page
def open_page(browser: Browser, url: str) -> Page:
    page = browser.new_page(viewport=VIEWPORT)
    page.goto(url)
    page.wait_for_function("window.__map && window.__map.firstPaint !== null", timeout=30000)
    return page


def first_paints(browser: Browser, url: str, runs: int) -> tuple[list[float], list[float]]:
    """Navigation start -> the map's first paint, and the tree's, in ms (cold caches)."""
    maps, trees = [], []
    for _ in range(runs):
        context = browser.new_context(viewport=VIEWPORT)
        page = context.new_page()
        page.goto(url)
        page.wait_for_function("window.__map && window.__map.firstPaint !== null",
                               timeout=30000)
        map_ms, tree_ms = page.evaluate(
            "[window.__map.firstPaint - performance.timeOrigin,"
            " window.__monitor.firstPaint - performance.timeOrigin]")
        maps.append(map_ms)
        trees.append(tree_ms)
        context.close()
    return maps, trees


@dataclass
class Latency:
    page_ms: list[float]
    floor_ms: list[float]
    unmatched: int
    merged: int


def pose_latency(page: Page, floor: FloorClient, published: Published,
                 seconds: float) -> Latency:
    """Pose published -> painted in ``page`` and -> arrived at the floor client, in ms."""
    page.evaluate("window.__map.paintTimes = []; window.__map.recordPaints = true")
    time.sleep(seconds)
    paints: list[list[Any]] = page.evaluate(
        "window.__map.recordPaints = false; window.__map.paintTimes")
    painted: dict[tuple[str, int], float] = {}
    for now_ms, seqs in paints:
        for ns, seq in seqs:
            if seq is not None:
                painted.setdefault((ns, seq), now_ms / 1000.0)
    first = {ns: min(seq for (name, seq) in painted if name == ns) for ns, _ in painted}
    page_ms, floor_ms, unmatched, merged = [], [], 0, 0
    for (ns, seq), (x, y, arrived) in sorted(floor.received.items()):
        if ns not in first or seq <= first[ns]:
            continue  # before recording started (its paint may be older than the window)
        sent = published.when(ns, x, y)
        if sent is None:
            unmatched += 1
            continue
        if (ns, seq) not in painted:
            merged += 1
            continue
        page_ms.append((painted[(ns, seq)] - sent) * 1000.0)
        floor_ms.append((arrived - sent) * 1000.0)
    if not page_ms:
        raise SystemExit(f"no pose was painted in {seconds:g} s ({len(paints)} frames, "
                         f"{len(floor.received)} rs received): is the map panel drawing?")
    return Latency(page_ms, floor_ms, unmatched, merged)


def metrics(cdp: Any) -> dict[str, float]:
    found = cdp.send("Performance.getMetrics")["metrics"]
    return {item["name"]: item["value"] for item in found}


def main_thread(page: Page, seconds: float, pairs: int) -> dict[str, list[float]]:
    """Main-thread and script ms per second, windows alternating between map and tree alone."""
    cdp = page.context.new_cdp_session(page)
    cdp.send("Performance.enable")
    figures: dict[str, list[float]] = {"map": [], "map_script": [], "tree": [], "tree_script": []}
    for _ in range(pairs):
        for shown in ("tree", "map"):
            maximised = page.evaluate("document.querySelector('main').dataset.max")
            if (shown == "tree") != (maximised == "tree"):
                page.click("#view button[data-max=tree]")
            page.wait_for_timeout(1000)  # settle: the map's opt-in and its first frames
            before = metrics(cdp)
            page.wait_for_timeout(seconds * 1000)
            after = metrics(cdp)
            span = after["Timestamp"] - before["Timestamp"]
            figures[shown].append(1000 * (after["TaskDuration"] - before["TaskDuration"]) / span)
            figures[shown + "_script"].append(
                1000 * (after["ScriptDuration"] - before["ScriptDuration"]) / span)
    if page.evaluate("document.querySelector('main').dataset.max") == "tree":
        page.click("#view button[data-max=tree]")
    cdp.detach()
    return figures


# ---------------------------------------------------------------------- driver
def wait_for(condition: Any, timeout: float, what: str) -> None:
    deadline = time.monotonic() + timeout
    while not condition():
        if time.monotonic() > deadline:
            raise SystemExit(f"timed out waiting for {what}")
        time.sleep(0.05)


def parser() -> argparse.ArgumentParser:
    """The benchmark's options."""
    return benchmark_options(__doc__, quick="1.5 s of poses, one page load, 1 s windows")


def main(argv: list[str] | None = None) -> int:
    args = parser().parse_args(argv)
    seconds, runs, window, pairs = (1.5, 1, 1.0, 1) if args.quick else (20.0, 5, 5.0, 3)
    chromium = shutil.which("chromium")
    if chromium is None:
        raise SystemExit("Debian's chromium is needed (apt install chromium)")
    if not MAP.is_file():
        raise SystemExit(f"{MAP} is needed (set CYBORG_SHARED to the shared data folder)")
    published = Published()
    with tempfile.TemporaryDirectory() as folder, Context(BusConfig.isolated()) as context:
        tree = Path(folder) / "tree.b3.json"
        tree.write_text(random_tree(TREE_NODES))
        robots = StandInRobots(context, published)
        runner = TreeRunnerNode(Node("tree_runner", "/robot1/bt", context=context), tree,
                                rate_hz=RATE_HZ)
        monitor = Monitor(Node("monitor", "/bench", context=context),
                          namespaces=["/robot1/bt"], host="127.0.0.1", port=0)
        runner.start()
        robots.start()
        monitor.start()
        url = monitor.urls()[0]
        floor = FloorClient(url)
        floor.start()
        try:
            wait_for(lambda: floor.robots_seen() == set(ROBOTS), 30, "all three robots' rs")
            with sync_playwright() as playwright:
                browser = playwright.chromium.launch(executable_path=chromium,
                                                     args=["--disable-gpu", "--disable-quic"])
                maps, trees = first_paints(browser, url, runs)
                page = open_page(browser, url)
                page.wait_for_timeout(1000)
                started = (floor.rs_messages, floor.scans, time.monotonic())
                latency = pose_latency(page, floor, published, seconds)
                rates = ((floor.rs_messages - started[0]) / (time.monotonic() - started[2]),
                         (floor.scans - started[1]) / (time.monotonic() - started[2]))
                cpu = main_thread(page, window, pairs)
                drawn = page.evaluate("window.__map.drawn")
                browser.close()
        finally:
            floor.stop.set()
            floor.thread.join(5)
            monitor.stop()
            robots.destroy()
            runner.destroy()
    header = (f"{len(ROBOTS)} robots at {RATE_HZ:g} Hz (pose + {BEAMS}-beam scan) on "
              f"{MAP.name} ({drawn['points']:,} points, {drawn['lines']:,} lines drawn), a "
              f"{TREE_NODES}-node tree at {RATE_HZ:g} Hz; {len(latency.page_ms)} poses painted "
              f"({latency.merged} merged into a later frame, {latency.unmatched} unmatched); "
              f"the monitor sent {rates[0]:.1f} rs/s ({rates[1]:.1f} with a scan)")
    met = report(header, latency, maps, trees, cpu, args.markdown)
    return 0 if met or args.quick else 1


def report(header: str, latency: Latency, maps: list[float], trees: list[float],
           cpu: dict[str, list[float]], markdown: bool) -> bool:
    """Prints the table and the verdicts; whether every goal is met."""
    ours, floor = latency.page_ms, latency.floor_ms
    p50, p99 = statistics.median(ours), percentile(ours, 0.99)
    floor50 = statistics.median(floor)
    map_paint, tree_paint = statistics.median(maps), statistics.median(trees)
    map_cpu, tree_cpu = statistics.median(cpu["map"]), statistics.median(cpu["tree"])
    rows = [
        ("pose published -> painted in Chromium (p50 / p95 / p99)",
         f"{p50:.1f} / {percentile(ours, .95):.1f} / {p99:.1f} ms",
         f"{p50 / floor50:.1f}x the floor", f"p50 <= {P50_GOAL_MS:g}, p99 <= {P99_GOAL_MS:g} ms"),
        ("transport floor: pose -> Python WebSocket client (p50 / p95 / p99)",
         f"{floor50:.1f} / {percentile(floor, .95):.1f} / {percentile(floor, .99):.1f} ms",
         "baseline", ""),
        ("first paint of the map, navigation -> columbia drawn (median)",
         f"{map_paint:.0f} ms", f"{map_paint / tree_paint:.2f}x the tree's",
         f"<= {FIRST_PAINT_GOAL_MS:g} ms"),
        ("first paint of the tree in the same loads (median)", f"{tree_paint:.0f} ms",
         "baseline", ""),
        ("page main thread, map with 3 robots + tree (median ms per s)",
         f"{map_cpu:.0f} ms/s (script {statistics.median(cpu['map_script']):.0f})",
         f"{map_cpu / tree_cpu:.1f}x the tree alone", ""),
        ("page main thread, tree view alone (median ms per s)",
         f"{tree_cpu:.0f} ms/s (script {statistics.median(cpu['tree_script']):.0f})",
         "baseline", ""),
    ]
    print_results(header, rows, markdown=markdown, widths=(68, 26, 22))
    ok_latency = p50 <= P50_GOAL_MS and p99 <= P99_GOAL_MS
    ok_paint = map_paint <= FIRST_PAINT_GOAL_MS
    def verdict(ok: bool) -> str:
        return "meets" if ok else "MISSES"
    print(f"\nlatency p50 {p50:.1f} ms, p99 {p99:.1f} ms ({verdict(ok_latency)} the goals); "
          f"first paint of the map {map_paint:.0f} ms ({verdict(ok_paint)} the goal); "
          f"main thread {map_cpu:.0f} against {tree_cpu:.0f} ms/s; windows: map "
          f"{[round(v) for v in cpu['map']]}, tree {[round(v) for v in cpu['tree']]}",
          file=sys.stdout if markdown else sys.stderr)
    return ok_latency and ok_paint


if __name__ == "__main__":
    raise SystemExit(main())
