"""Simulation speed with people walking and the simulated camera on (columbia.map in ../shared).

    python3 -m benchmarks.sim_people [--quick] [--markdown] [--map PATH] [--people N]

The robot patrols the map's goals, as in benchmarks/sim_nav.py (laser 541 beams, physics 50 Hz,
laser and navigation 10 Hz), with 10 people walking at random among the goals (0.5 to 1.5 m/s,
pausing, keeping out of the robot's way; the laser sees them) and the simulated camera taking
a frame every 0.1 simulated seconds of the people in view (occlusion rays, noise, misses,
boxes), as its bus node does. Result in simulated seconds per wall second, and per second of the
process's CPU time: on a shared machine the wall clock also counts the time the process waited
for a core, so the goal is judged on the CPU figure (what the simulation costs, the speed on a
free core), the load average printed beside. Baseline in the same run: the same patrol with
nobody walking and no camera. Goal: >= 200x real time.
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

from benchmarks import SHARED, benchmark_options
from benchmarks.patrol import patrol_goals
from benchmarks.results_table import print_results
from cyborg.nav.arnl_map import ArnlMap, read_map
from cyborg.sim.camera import SimCamera
from cyborg.sim.people import Crowd
from cyborg.sim.people_sources import random_people
from cyborg.sim.sights import crowd_sights
from cyborg.sim.simulator import Simulator


class Result:
    """What one patrol measured: its speed (wall and CPU), goals reached, frames, detections."""

    def __init__(self, speed: float, cpu_speed: float, reached: int, frames: int,
                 detections: int, routes: int) -> None:
        self.speed, self.cpu_speed, self.reached, self.frames = speed, cpu_speed, reached, frames
        self.detections, self.routes = detections, routes


def patrol(arnl_map: ArnlMap, minutes: float, people: int) -> Result:
    """The robot patrols for ``minutes`` with ``people`` walking and the camera on (if any)."""
    sim = Simulator(arnl_map)
    camera = None
    if people:
        pose = sim.pose
        sim.crowd = Crowd(sim.planner, random_people(arnl_map, sim.planner, people, seed=1,
                                                     keep_away=[(pose.x, pose.y)]), seed=1)
        laser = sim.laser
        camera = SimCamera(laser.occupied, laser.origin, laser.resolution, seed=1)
    counts = {"frames": 0, "detections": 0}
    due = [0.0]

    def step() -> None:
        sim.step()
        if camera is not None and sim.time >= due[0]:
            due[0] += 1.0 / camera.spec.rate
            pose = sim.pose
            seen = camera.observe(pose.x, pose.y, pose.theta, crowd_sights(sim.crowd),
                                  sim.others)
            counts["frames"] += 1
            counts["detections"] += len(seen)

    for _ in range(50):
        step()  # compiled kernels loaded, caches warm
    started, cpu, begin = time.perf_counter(), time.process_time(), sim.time
    reached = patrol_goals(sim, begin + minutes * 60, step)
    speed = (sim.time - begin) / (time.perf_counter() - started)
    cpu_speed = (sim.time - begin) / (time.process_time() - cpu)
    routes = sim.crowd.routes.planned if sim.crowd is not None else 0
    return Result(speed, cpu_speed, reached, counts["frames"], counts["detections"], routes)


def parser() -> argparse.ArgumentParser:
    """The benchmark's options."""
    options = benchmark_options(__doc__, quick="1 simulated minute")
    options.add_argument("--map", type=Path, default=SHARED / "maps" / "columbia.map")
    options.add_argument("--people", type=int, default=10, help="people walking (default 10)")
    return options


def main(argv: list[str] | None = None) -> None:
    args = parser().parse_args(argv)
    arnl_map = read_map(args.map)
    minutes = 1.0 if args.quick else 10.0
    ours = patrol(arnl_map, minutes, args.people)
    base = patrol(arnl_map, minutes, 0)
    rows = [
        (f"simulation, {args.people} people, laser and camera (x real time)",
         f"{ours.speed:.0f}x", f"{ours.speed / base.speed:.2f}x baseline",
         f"{ours.reached} goals in {minutes:g} min; {ours.frames} frames, "
         f"{ours.detections} detections; {ours.routes} routes planned"),
        ("the same, per CPU second (x real time on a free core)", f"{ours.cpu_speed:.0f}x",
         f"{ours.cpu_speed / base.cpu_speed:.2f}x baseline", "sim time / process CPU time"),
        ("simulation, nobody, laser only (baseline)", f"{base.speed:.0f}x", "1.00x baseline",
         f"{base.reached} goals in {minutes:g} min"),
        ("the same, per CPU second", f"{base.cpu_speed:.0f}x", "1.00x baseline",
         "sim time / process CPU time"),
    ]
    print_results("", rows, markdown=args.markdown, widths=(52, 7, 16),
                  columns=("measurement", "value", "ratio", "note"))
    print(f"\nsimulation with {args.people} people and the camera {ours.speed:.0f}x real time, "
          f"{ours.cpu_speed:.0f}x per CPU second "
          f"(goal >= 200x: {'met' if ours.cpu_speed >= 200 else 'NOT met'}; load average "
          f"{os.getloadavg()[0]:.1f})")


if __name__ == "__main__":
    main()
