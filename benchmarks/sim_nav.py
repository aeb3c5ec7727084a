"""Simulation speed and planning time on columbia.map (an ARNL map in ../shared/maps).

    python3 -m benchmarks.sim_nav [--quick] [--markdown] [--map PATH]

* **simulation**: the robot patrols the map's goals with the laser on (541 beams, 270°, 30 m;
  physics 50 Hz, laser and navigation 10 Hz); result in simulated seconds per wall second.
  Baseline in the same run: the same simulator with a pure-numpy laser (half-cell ray march),
  the way a simulator without a compiled raycaster does it. Goal: ≥ 200x real time.
* **planning**: every pair of reachable goals (far goals included: up to 64 m of path), median
  and worst planning time. Baseline in the same run: a plain-Python A* (heapq) on the same cost
  grid, for the farthest pair. Goal: ≤ 50 ms for far goals. The same pairs again with three
  people standing on each path (temporary obstacles, :mod:`cyborg.nav.temporary_obstacles`):
  median and worst, against the same ≤ 50 ms.
"""

from __future__ import annotations

import argparse
import heapq
import itertools
import math
import statistics
import time
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np

from benchmarks import SHARED, benchmark_options
from benchmarks.patrol import patrol_goals
from benchmarks.results_table import print_results
from cyborg.nav.arnl_map import ArnlMap, read_map
from cyborg.nav.geometry import Pose2D
from cyborg.nav.planner import Planner
from cyborg.nav.temporary_obstacles import ObstacleSettings
from cyborg.sim.laser import Laser
from cyborg.sim.simulator import Simulator


def numpy_laser_scan(laser: Laser) -> Callable[[float, float, float], np.ndarray]:
    """A ray-marching laser in numpy (the baseline): every beam sampled at half a cell."""
    spec = laser.spec
    steps = np.arange(0.0, spec.range_max, laser.resolution / 2)
    relative = spec.angles()
    rows, columns = laser.occupied.shape

    def scan(x: float, y: float, theta: float, bodies: Sequence[np.ndarray] = (),
             circles: np.ndarray | None = None) -> np.ndarray:
        # the walls only: this patrol has no other robots and nobody walking
        assert not bodies and (circles is None or not len(circles))
        sx, sy = x + spec.mount_x * math.cos(theta), y + spec.mount_x * math.sin(theta)
        angles = relative + theta
        px = sx + np.outer(np.cos(angles), steps)
        py = sy + np.outer(np.sin(angles), steps)
        c = np.clip(((px - laser.origin[0]) / laser.resolution).astype(np.int64), 0, columns - 1)
        r = np.clip(((py - laser.origin[1]) / laser.resolution).astype(np.int64), 0, rows - 1)
        hit = laser.occupied[r, c]
        first = np.where(hit.any(axis=1), hit.argmax(axis=1), len(steps))
        ranges = np.where(first < len(steps), steps[np.minimum(first, len(steps) - 1)],
                          spec.range_max + 1.0)
        return ranges
    return scan


def patrol_speed(arnl_map: ArnlMap, minutes: float, numpy_laser: bool) -> tuple[float, int]:
    """Simulated seconds per wall second, and goals reached."""
    sim = Simulator(arnl_map)
    if numpy_laser:
        sim.laser.scan = numpy_laser_scan(sim.laser)  # type: ignore[method-assign, assignment]
    sim.run(1.0)  # compiled kernels loaded, caches warm
    started, begin = time.perf_counter(), sim.time
    reached = patrol_goals(sim, begin + minutes * 60)
    return (sim.time - begin) / (time.perf_counter() - started), reached


def python_astar(cost: np.ndarray, start: tuple[int, int], goal: tuple[int, int]) -> float:
    """The baseline planner: textbook A* in plain Python on the same grid and costs."""
    rows, columns = cost.shape
    grid = cost.tolist()
    best = {start: 0.0}
    heap = [(0.0, start)]
    done = set()
    moves = [(dr, dc, math.hypot(dr, dc)) for dr in (-1, 0, 1) for dc in (-1, 0, 1) if dr or dc]
    while heap:
        _f, cell = heapq.heappop(heap)
        if cell == goal:
            return best[cell]
        if cell in done:
            continue
        done.add(cell)
        r, c = cell
        for dr, dc, length in moves:
            nr, nc = r + dr, c + dc
            if not (0 <= nr < rows and 0 <= nc < columns) or not math.isfinite(grid[nr][nc]):
                continue
            g = best[cell] + length * 0.5 * (grid[r][c] + grid[nr][nc])
            if g < best.get((nr, nc), math.inf):
                best[(nr, nc)] = g
                h = math.hypot(nr - goal[0], nc - goal[1])
                heapq.heappush(heap, (g + h, (nr, nc)))
    return math.inf


def planning(arnl_map: ArnlMap) -> tuple[list[float], float, float, float, list[float]]:
    """Plan times of every reachable pair, the farthest pair's, and with people on the paths."""
    planner = Planner(arnl_map)
    poses = [Pose2D(item.x, item.y) for item in arnl_map.goals()]
    planner.plan(poses[0], poses[1])  # load the compiled kernels
    times, far = [], (0.0, poses[0], poses[1], 0.0)
    with_people: list[float] = []
    keep_out = ObstacleSettings().keep_out
    for start, goal in itertools.permutations(poses, 2):
        result = planner.plan(start, goal)
        if result.found and result.path is not None:
            times.append(result.planning_time)
            if result.length > far[0]:
                far = (result.length, start, goal, result.planning_time)
            people = np.array([[*result.path.point_at(result.length * share), keep_out]
                               for share in (0.25, 0.5, 0.75)])
            with_people.append(planner.plan(start, goal, discs=people).planning_time)
    length, start, goal, ours = far
    cost = planner.cost.copy()
    planner._open_escape(cost, planner.clearance, start)
    planner._open_escape(cost, planner.clearance, goal)
    began = time.perf_counter()
    python_astar(cost, planner.grid.cell(start.x, start.y), planner.grid.cell(goal.x, goal.y))
    baseline = time.perf_counter() - began
    return times, length, ours, baseline, with_people


def parser() -> argparse.ArgumentParser:
    """The benchmark's options."""
    options = benchmark_options(__doc__, quick="1 simulated minute, the numpy baseline 6 s")
    options.add_argument("--map", type=Path, default=SHARED / "maps" / "columbia.map")
    return options


def main(argv: list[str] | None = None) -> None:
    args = parser().parse_args(argv)
    arnl_map = read_map(args.map)
    minutes, base_minutes = (1.0, 0.1) if args.quick else (10.0, 2.0)
    ours, reached = patrol_speed(arnl_map, minutes, numpy_laser=False)
    base, base_reached = patrol_speed(arnl_map, base_minutes, numpy_laser=True)
    times, far_length, far_ours, far_python, with_people = planning(arnl_map)
    rows = [
        ("simulation, compiled laser (x real time)", f"{ours:.0f}x",
         f"{ours / base:.1f}x baseline", f"{reached} goals in {minutes:g} min"),
        ("simulation, numpy ray-march laser (baseline)", f"{base:.0f}x", "1.0x baseline",
         f"{base_reached} goals in {base_minutes:g} min"),
        ("planning, all goal pairs: median ms", f"{statistics.median(times) * 1000:.1f}", "",
         f"{len(times)} plans"),
        ("planning, all goal pairs: worst ms", f"{max(times) * 1000:.1f}", "", ""),
        (f"planning, farthest pair ({far_length:.1f} m): ms", f"{far_ours * 1000:.1f}",
         f"{far_python / far_ours:.0f}x faster than baseline", ""),
        ("planning, farthest pair, plain-Python A* (baseline): ms", f"{far_python * 1000:.0f}",
         "1.0x baseline", ""),
        ("planning, three people on each path: median ms",
         f"{statistics.median(with_people) * 1000:.1f}", "", f"{len(with_people)} plans"),
        ("planning, three people on each path: worst ms", f"{max(with_people) * 1000:.1f}", "",
         ""),
    ]
    print_results("", rows, markdown=args.markdown, widths=(58, 9, 30),
                  columns=("measurement", "value", "ratio", "note"))
    print(f"\nsimulation {ours:.0f}x real time (goal >= 200x: {'met' if ours >= 200 else 'NOT met'}"
          f"); worst plan {max(times) * 1000:.1f} ms (goal <= 50 ms: "
          f"{'met' if max(times) <= 0.05 else 'NOT met'}); with three people on the path "
          f"{max(with_people) * 1000:.1f} ms ({'met' if max(with_people) <= 0.05 else 'NOT met'})")


if __name__ == "__main__":
    main()
