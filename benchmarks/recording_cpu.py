"""What recording `cyborg up`'s default topics costs: CPU as % of one core, against 5 %.

    python3 -m benchmarks.recording_cpu               # 60 s each way, after a 10 s warm-up
    python3 -m benchmarks.recording_cpu --seconds 20  # a shorter measure
    python3 -m benchmarks.recording_cpu --quick       # a smoke test: 1 s each way, after 1 s
    python3 -m benchmarks.recording_cpu --markdown    # the rows for docs/benchmarks.md
    python3 -m benchmarks.recording_cpu --profile     # and where the in-process recorder's
                                                      # thread spends it (cProfile)

The system is what ``cyborg up --no-detector --no-monitor`` starts (the simulated Pioneer LX,
the tree runner, at the default pace), recorded with every default topic (images left out,
as a recording of all topics leaves them). Measured two ways, one after the other:

* **in the same process**, as ``cyborg up --record`` runs it: the system and the recorder
  component in this process; the cost is the CPU time of the recorder node's thread (from
  ``/proc/self/task/<tid>/stat``), which serialises the in-process messages, writes them and
  runs the recorder's timers. The work left on the publishers' threads (queueing a message for
  the recorder) is not in it; it is a few microseconds a message.
* **as its own process**, as ``cyborg record`` beside a running ``cyborg up``: ``cyborg up``
  in one process listening on a free loopback port, ``cyborg record`` in another joined to
  it; the cost is the whole recorder process's CPU time (``/proc/<pid>/stat``: receiving over
  Zenoh, its threads, writing).

Each reports the recorder's CPU seconds per wall second over ``--seconds`` after the warm-up,
the messages and MB of CDR a second it wrote, and the goal: at most 5 % of one core.
"""

from __future__ import annotations

import argparse
import cProfile
import os
import pstats
import socket
import subprocess
import sys
import tempfile
import threading
import time
from dataclasses import dataclass
from pathlib import Path

from mcap.reader import make_reader

from benchmarks import benchmark_options
from benchmarks.results_table import print_results
from cyborg.app.cli import build_parser
from cyborg.app.launch import Launch
from cyborg.app.memory import limit_malloc_arenas
from cyborg.app.up import up_description
from cyborg.bus import BusConfig, Context
from cyborg.record.component import RunningRecorder

GOAL = 5.0
"""% of one core that recording cyborg up's default topics may cost."""
TICKS = os.sysconf("SC_CLK_TCK")


@dataclass
class Cost:
    """The recorder's CPU over a wall-clock window, and what it wrote meanwhile."""

    cpu: float
    wall: float
    messages: int
    megabytes: float

    @property
    def core(self) -> float:
        """CPU seconds per wall second, as % of one core."""
        return self.cpu / self.wall * 100


def cpu_seconds(stat: Path) -> float:
    """User plus system CPU seconds from a ``/proc/.../stat`` file."""
    fields = stat.read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / TICKS


def in_process(seconds: float, warm_up: float, folder: Path, profile: bool) -> Cost:
    """``cyborg up --record`` in this process; the recorder thread's CPU."""
    words = ["up", "--no-detector", "--no-monitor", "--record", str(folder / "inproc.mcap")]
    with Context(BusConfig.isolated()) as context:
        launch = Launch(up_description(build_parser().parse_args(words)), context)
        launch.start()
        try:
            recorder = next(item for item in launch.running
                            if isinstance(item, RunningRecorder)).recorder
            thread = recorder.node.callbacks._thread
            stat = Path(f"/proc/self/task/{thread.native_id}/stat")
            profiler = cProfile.Profile() if profile else None
            if profiler is not None:  # on the recorder's own thread, between two callbacks
                recorder.node.callbacks.submit(profiler.enable)
            time.sleep(warm_up)
            stats = recorder.stats
            cpu, wall, messages, size = (cpu_seconds(stat), time.perf_counter(),
                                         stats.messages, stats.bytes)
            time.sleep(seconds)
            cost = Cost(cpu_seconds(stat) - cpu, time.perf_counter() - wall,
                        stats.messages - messages, (stats.bytes - size) / 1e6)
            if profiler is not None:
                done = threading.Event()

                def stop() -> None:
                    profiler.disable()
                    done.set()
                recorder.node.callbacks.submit(stop)
                done.wait(10)
                pstats.Stats(profiler, stream=sys.stderr).sort_stats("tottime").print_stats(25)
        finally:
            launch.stop()
    return cost


def own_process(seconds: float, warm_up: float, folder: Path) -> Cost:
    """``cyborg record`` beside ``cyborg up``; the recorder process's CPU."""
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        endpoint = f"tcp/127.0.0.1:{probe.getsockname()[1]}"
    path = folder / "record.mcap"
    cyborg = [sys.executable, "-m", "cyborg"]
    system = subprocess.Popen([*cyborg, "up", "--no-detector", "--no-monitor", "--listen",
                               endpoint], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        time.sleep(3)  # the system's nodes up, before the recorder looks at the graph
        record = subprocess.Popen([*cyborg, "record", "-o", str(path), "--connect", endpoint],
                                  stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        try:
            stat = Path(f"/proc/{record.pid}/stat")
            started = time.monotonic()
            while not path.exists():  # cyborg record has started and opened its file
                if record.poll() is not None or time.monotonic() - started > 60:
                    raise RuntimeError(f"cyborg record did not start writing {path}")
                time.sleep(0.1)
            time.sleep(warm_up)
            cpu, wall, log_from = cpu_seconds(stat), time.perf_counter(), time.time_ns()
            time.sleep(seconds)
            cost = Cost(cpu_seconds(stat) - cpu, time.perf_counter() - wall, 0, 0.0)
            log_to = time.time_ns()
        finally:
            record.terminate()
            record.wait(30)
    finally:
        system.terminate()
        system.wait(30)
    with open(path, "rb") as stream:  # what it wrote in the window, by log time
        for _schema, _channel, message in make_reader(stream).iter_messages(
                starting_at=log_from, ending_before=log_to):
            cost.messages += 1
            cost.megabytes += len(message.data) / 1e6
    return cost


def describe(cost: Cost) -> tuple[str, str]:
    """The result and ratio columns of a cost."""
    return (f"{cost.core:.2f} % of one core ({cost.cpu:.2f} CPU s in {cost.wall:.0f} s); "
            f"{cost.messages / cost.wall:.0f} msgs/s, {cost.megabytes / cost.wall:.3f} MB/s",
            f"{cost.core / GOAL:.2f} of the goal")


def parser() -> argparse.ArgumentParser:
    """The benchmark's options."""
    options = benchmark_options(__doc__, quick="--seconds 1 --warm-up 1")
    options.add_argument("--seconds", type=float, default=60.0,
                         help="wall seconds measured each way (default 60)")
    options.add_argument("--warm-up", type=float, default=10.0,
                         help="seconds of recording before measuring (default 10)")
    options.add_argument("--profile", action="store_true",
                         help="print where the in-process recorder's thread spends its time")
    return options


def main(argv: list[str] | None = None) -> None:
    args = parser().parse_args(argv)
    if args.quick:
        args.seconds, args.warm_up = 1.0, 1.0
    limit_malloc_arenas()  # as `cyborg` does on start (cyborg.app.memory)
    with tempfile.TemporaryDirectory() as folder:
        inside = in_process(args.seconds, args.warm_up, Path(folder), args.profile)
        beside = own_process(args.seconds, args.warm_up, Path(folder))
    rows = []
    for name, cost in (("recorder in cyborg up's process (cyborg up --record)", inside),
                       ("recorder as its own process (cyborg record)", beside)):
        result, ratio = describe(cost)
        rows.append((name, result, ratio,
                     f"<= {GOAL:g} % of one core: {'meets' if cost.core <= GOAL else 'MISSES'}"))
    print_results(f"Recording cyborg up's default topics, images left out "
                  f"({time.strftime('%Y-%m-%d')})", rows, markdown=args.markdown,
                  widths=(54, 70, 16))


if __name__ == "__main__":
    main()
