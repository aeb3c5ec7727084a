"""Soak: the whole `cyborg up` system as fast as the machine allows, for a wall-clock time.

    python3 -m benchmarks.soak [--minutes 60] [--markdown] [--detector]
    python3 -m benchmarks.soak --quick     # a smoke test: 3 s (--minutes 0.05)

Starts what `cyborg up` starts — the simulated Pioneer LX on the bundled campus map, the tree
runner with the bundled mission on modes on simulated time, the web monitor (on a free
loopback port) and, with ``--detector``, the camera and the detector — in this process, with
the simulation at full speed (``--speed 0``), and reports:

* **memory**: resident set size after the warm-up (the baseline, measured in the same run:
  the first tenth of the run, at most five minutes) and at the end, and the growth between
  them as a ratio. Goal: at most 1.10 (10 % growth) over an hour.
  The process limits glibc's malloc arenas as ``cyborg`` does (:mod:`cyborg.app.memory`);
  run with ``MALLOC_ARENA_MAX=8`` (or more) to see the growth without that limit.
* **work done**: simulated hours, goals reached, charges (dockings), collisions (bumps; goal 0).

A soak is not a test: it takes as long as it is told to, and is recorded in
docs/benchmarks.md with the command that produced it.
"""

from __future__ import annotations

import argparse
import time
from dataclasses import dataclass, field
from pathlib import Path

from benchmarks import benchmark_options
from cyborg.app.cli import build_parser
from cyborg.app.launch import Launch
from cyborg.app.memory import limit_malloc_arenas
from cyborg.app.up import up_description
from cyborg.bt import SUCCESS
from cyborg.bt.snapshot import TickSnapshot
from cyborg.bus import BusConfig, Context
from cyborg.modes import ModeMachine
from cyborg.runner.component import RunningTree
from cyborg.sim.component import RunningSimulator


def rss_mib() -> float:
    """This process's resident set size in MiB (Linux /proc)."""
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024
    raise RuntimeError("no VmRSS in /proc/self/status")


@dataclass
class Tally:
    """What the tree did, from its tick snapshots."""

    labels: dict[str, str]
    goals: int = 0
    last_goal: str = ""
    seen: list[str] = field(default_factory=list)

    def tick(self, snapshot: TickSnapshot) -> None:
        for uid, status in snapshot.visited:
            label = self.labels.get(uid, "")
            if status is SUCCESS and label.startswith("MoveTo "):
                self.goals += 1
                self.last_goal = label.removeprefix("MoveTo ")


def soak(minutes: float, detector: bool) -> dict[str, float]:
    words = ["up", "--speed", "0", "--monitor-port", "0"]
    if not detector:
        words.append("--no-detector")
    args = build_parser().parse_args(words)
    with Context(BusConfig.isolated()) as context:
        launch = Launch(up_description(args), context)
        launch.start()
        try:
            sim = next(item for item in launch.running
                       if isinstance(item, RunningSimulator)).loop.simulator
            runner = next(item for item in launch.running if isinstance(item, RunningTree))
            ticked = runner.runner.ticked  # the mission's mode machine, or a plain tree
            trees = ticked.trees.values() if isinstance(ticked, ModeMachine) else [ticked]
            tally = Tally({node.uid: node.label for tree in trees for node in tree})
            runner.runner.runner.add_listener(tally.tick)
            started = time.monotonic()
            total = minutes * 60
            warm_up = min(total / 10, 300.0)
            time.sleep(warm_up)
            rss_start, sim_start = rss_mib(), sim.time
            peak = rss_start
            while time.monotonic() - started < total:
                time.sleep(min(5.0, max(total - (time.monotonic() - started), 0.0)))
                peak = max(peak, rss_mib())
            rss_end = rss_mib()
            return {"minutes": minutes, "rss_start": rss_start, "rss_end": rss_end,
                    "rss_peak": peak, "growth": rss_end / rss_start,
                    "sim_hours": sim.time / 3600, "measured_hours": (sim.time - sim_start) / 3600,
                    "goals": tally.goals, "charges": sim.docking.docks,
                    "collisions": sim.base.bumps}
        finally:
            launch.stop()


def parser() -> argparse.ArgumentParser:
    """The benchmark's options."""
    options = benchmark_options(__doc__, quick="--minutes 0.05")
    options.add_argument("--minutes", type=float, default=60.0, help="wall-clock minutes")
    options.add_argument("--detector", action="store_true", help="run the camera and detector")
    return options


def main(argv: list[str] | None = None) -> None:
    args = parser().parse_args(argv)
    if args.quick:
        args.minutes = 0.05
    limit_malloc_arenas()  # as `cyborg` does on start (cyborg.app.memory)
    result = soak(args.minutes, args.detector)
    verdict = "meets" if result["growth"] <= 1.10 and result["collisions"] == 0 else "MISSES"
    if args.markdown:
        print("| wall | RSS after warm-up | RSS at end (peak) | growth | simulated | goals | "
              "charges | collisions |")
        print("| --: | --: | --: | --: | --: | --: | --: | --: |")
        print(f"| {result['minutes']:g} min | {result['rss_start']:.0f} MiB | "
              f"{result['rss_end']:.0f} MiB ({result['rss_peak']:.0f}) | "
              f"{result['growth']:.3f}x | {result['sim_hours']:.1f} h | {result['goals']:.0f} | "
              f"{result['charges']:.0f} | {result['collisions']:.0f} |")
    else:
        print(f"{result['minutes']:g} min wall, {result['sim_hours']:.1f} simulated hours: "
              f"{result['goals']:.0f} goals, {result['charges']:.0f} charges, "
              f"{result['collisions']:.0f} collisions")
        print(f"RSS {result['rss_start']:.0f} MiB after warm-up -> {result['rss_end']:.0f} MiB "
              f"at the end (peak {result['rss_peak']:.0f}): {result['growth']:.3f}x the "
              f"warm-up baseline; goal <= 1.10x and no collision: {verdict}")


if __name__ == "__main__":
    main()
