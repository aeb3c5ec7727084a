"""Where the tracker puts people, against where they are: the simulator's camera, end to end.

    python3 -m benchmarks.perception_accuracy             # 5 simulated minutes, about 15 s
    python3 -m benchmarks.perception_accuracy --quick     # 15 simulated seconds
    python3 -m benchmarks.perception_accuracy --markdown  # the table as Markdown

The robot patrols the map's goals (columbia.map in ../shared) with 10 people walking at random
among them (0.5 to 1.5 m/s, pausing, keeping out of its way), as in benchmarks/sim_people.py.
Every 0.1 simulated seconds the simulated camera (:class:`~cyborg.sim.camera.SimCamera`: the
ZED's field of view and range, its depth and bearing noise, misses and occlusion) takes a frame,
and the frame goes the way the robot's tracker takes it, without the bus: the
``cyborg_msgs/Predictions`` message the camera node publishes, screened
(:func:`~cyborg.perception.screening.screen`), placed on the map with the robot's pose at the
frame (:func:`~cyborg.perception.sighting.locate`) and tracked
(:meth:`~cyborg.perception.tracker.Tracker.update`).

After each frame every tracked person seen in that frame is compared with the true person
nearest to it at that moment: the error is the distance between the two, binned by the true
person's distance from the robot (up to 5 m, 5 to 10 m, beyond). The same is done for the
sightings themselves (one frame's detection placed on the map, before tracking), which shows
what the tracker's smoothing adds. Everything is seeded: the same run gives the same figures.

Goal (issue 24): the tracked people's median error <= 0.3 m within 5 m of the robot, reported
with the 90th percentile.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

from benchmarks import SHARED, benchmark_options
from benchmarks.patrol import patrol_goals
from cyborg.bus.msgs.builtin_interfaces.msg import Time
from cyborg.bus.msgs.std_msgs.msg import Header
from cyborg.interfaces.detection_messages import predictions_message
from cyborg.nav.arnl_map import ArnlMap, read_map
from cyborg.perception import RobotPose, Tracker, locate, screen
from cyborg.sim.camera import SimCamera
from cyborg.sim.people import Crowd
from cyborg.sim.people_sources import random_people
from cyborg.sim.sights import crowd_sights
from cyborg.sim.simulator import Simulator

BANDS = ((0.0, 5.0, "<= 5 m"), (5.0, 10.0, "5-10 m"), (10.0, math.inf, "> 10 m"))
"""Ranges (m, from the robot to the true person) the errors are reported in."""


class Errors:
    """Position errors (m) of tracked people and of single sightings, by range band."""

    def __init__(self) -> None:
        self.tracked: dict[str, list[float]] = {name: [] for *_, name in BANDS}
        self.sighted: dict[str, list[float]] = {name: [] for *_, name in BANDS}
        self.frames = 0

    def add(self, errors: dict[str, list[float]], found: np.ndarray, truth: np.ndarray,
            robot: tuple[float, float]) -> None:
        """Each of ``found`` ((N, 2), m) against the nearest of ``truth``, by its range."""
        if not len(found) or not len(truth):
            return
        gaps = np.hypot(found[:, None, 0] - truth[None, :, 0],
                        found[:, None, 1] - truth[None, :, 1])
        nearest = np.argmin(gaps, axis=1)
        ranges = np.hypot(truth[nearest, 0] - robot[0], truth[nearest, 1] - robot[1])
        for error, distance in zip(gaps[np.arange(len(found)), nearest], ranges, strict=True):
            name = next(name for low, high, name in BANDS if low <= distance < high)
            errors[name].append(float(error))


def measure(arnl_map: ArnlMap, minutes: float, people: int, seed: int) -> Errors:
    """Patrol ``minutes`` simulated minutes with ``people`` walking; the errors seen."""
    sim = Simulator(arnl_map)
    start = sim.pose
    crowd = Crowd(sim.planner, random_people(arnl_map, sim.planner, people, seed=seed,
                                             keep_away=[(start.x, start.y)]), seed=seed)
    sim.crowd = crowd
    laser = sim.laser
    camera = SimCamera(laser.occupied, laser.origin, laser.resolution, seed=seed)
    tracker, errors = Tracker(), Errors()
    due = [0.0]

    def step() -> None:
        sim.step()
        if sim.time + 1e-9 < due[0]:
            return
        due[0] += 1.0 / camera.spec.rate
        pose, stamp_ns = sim.pose, round(sim.time * 1e9)
        seen = camera.observe(pose.x, pose.y, pose.theta, crowd_sights(crowd), sim.others)
        header = Header(stamp=Time(sec=stamp_ns // 1_000_000_000,
                                   nanosec=stamp_ns % 1_000_000_000), frame_id="camera")
        detections, _rejected = screen(predictions_message(seen, header, stamp_ns).predictions)
        sightings = locate(detections, RobotPose(pose.x, pose.y, pose.theta))
        tracker.update(stamp_ns / 1e9, sightings)
        truth, robot = crowd.positions, (pose.x, pose.y)
        errors.add(errors.sighted, np.array([(s.x, s.y) for s in sightings]).reshape(-1, 2),
                   truth, robot)
        fresh = [(item.x, item.y) for item in tracker.objects()
                 if abs(item.last_seen - stamp_ns / 1e9) < 1e-9]
        errors.add(errors.tracked, np.array(fresh).reshape(-1, 2), truth, robot)
        errors.frames += 1

    patrol_goals(sim, minutes * 60, step)
    return errors


def _figures(values: list[float]) -> str:
    if not values:
        return "none"
    median, p90 = np.percentile(values, [50, 90])
    return f"median {median:.2f} m, p90 {p90:.2f} m ({len(values)})"


def parser() -> argparse.ArgumentParser:
    """The benchmark's options."""
    options = benchmark_options(__doc__, quick="15 simulated seconds")
    options.add_argument("--map", type=Path, default=SHARED / "maps" / "columbia.map")
    options.add_argument("--people", type=int, default=10, help="people walking (default 10)")
    options.add_argument("--seed", type=int, default=1, help="the people's and camera's seed")
    return options


def main(argv: list[str] | None = None) -> None:
    args = parser().parse_args(argv)
    minutes = 0.25 if args.quick else 5.0
    errors = measure(read_map(args.map), minutes, args.people, args.seed)
    rows = [(f"tracked people, {name} from the robot", _figures(errors.tracked[name]))
            for *_, name in BANDS[:2]]
    rows += [(f"single sightings, {name} from the robot", _figures(errors.sighted[name]))
             for *_, name in BANDS[:2]]
    if args.markdown:
        print("| position error (m) | median, 90th percentile (samples) |\n| --- | --- |")
        for row in rows:
            print("| " + " | ".join(row) + " |")
    else:
        for name, value in rows:
            print(f"{name:42} {value}")
    near = errors.tracked[BANDS[0][2]]
    median = float(np.median(near)) if near else math.inf
    print(f"\n{errors.frames} frames in {minutes:g} simulated min; tracked people within 5 m: "
          f"median error {median:.2f} m (goal <= 0.3 m: {'met' if median <= 0.3 else 'NOT met'})")


if __name__ == "__main__":
    main()
