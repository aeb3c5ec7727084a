"""The project's speed benchmarks, each against a named baseline measured in the same run.

Each benchmark is a module run from the repository root, and each has the same options::

    python3 -m benchmarks.bt_tick             # the full run, the figures in docs/benchmarks.md
    python3 -m benchmarks.bt_tick --quick     # a smoke test of a few seconds, not a measurement
    python3 -m benchmarks.bt_tick --markdown  # the full run's table, for docs/benchmarks.md
    python3 -m benchmarks --quick             # every benchmark's quick variant, one by one

A quick variant runs every part of its benchmark on very little work: it shows that the
benchmark runs and what it prints, and exits 0 whatever its figures say of the goals (the
full run exits 1 where a benchmark judges a goal missed). Each benchmark's module gives its
options through a function ``parser()``, built on :func:`benchmark_options`, against which
the documentation's commands are checked (tests/test_doc_commands.py).
"""

import argparse
import os
import sys
from pathlib import Path

SHARED = Path(os.environ.get("CYBORG_SHARED", Path(__file__).resolve().parents[2] / "shared"))
"""The project's shared data (maps, trees, models): ``$CYBORG_SHARED``, or ``../shared`` beside
the repository."""

BENCHMARKS: dict[str, str] = {
    "bt_tick": "behaviour-tree tick cost against py_trees",
    "bus_transport": "a camera frame between processes against the memcpy floor",
    "sim_nav": "the simulator's speed with the laser, and planning on columbia.map",
    "sim_people": "the simulator's speed with 10 people walking and the camera on",
    "perception_accuracy": "tracked people's position error on the simulated camera",
    "perception": "the tracker's CPU per frame at 20 detections",
    "modes": "a mode switch and the mode machine's share of a tick",
    "monitor_web": "tick to painted in Chromium, and the tree's first paint",
    "monitor_map": "pose to painted on the map, and the map's first paint",
    "detector": "the detector end to end against bare inference and the 2018 approach",
    "recording": "the recorder's file writer by compression",
    "recording_cpu": "the recorder's CPU on cyborg up's default topics",
    "recording_camera": "recording the camera's full stream",
    "replay": "cyborg play's timing against a bare sleep loop",
    "cli_startup": "the command line's start-up time and memory against import zenoh",
    "soak": "cyborg up at full speed: memory growth and collisions",
}
"""Every benchmark (module ``benchmarks.NAME``) and what it measures, in the order of
docs/benchmarks.md's sections."""


def benchmark_options(doc: str | None, *, quick: str) -> argparse.ArgumentParser:
    """A benchmark's parser, with the options every benchmark has.

    ``doc``: the benchmark's docstring (its first line describes the command); ``quick``: what
    its ``--quick`` does, for the help. A benchmark adds its own options to the parser.
    """
    running = getattr(sys.modules.get("__main__"), "__spec__", None)  # python3 -m NAME
    prog = f"python3 -m {running.name}" if running and running.name.startswith("benchmarks.") \
        else None  # its usage line says how it is run
    options = argparse.ArgumentParser(prog=prog, description=(doc or "").strip().splitlines()[0])
    options.add_argument("--quick", action="store_true",
                         help=f"a smoke test, not a measurement ({quick}); exits 0 whatever "
                              "the figures say of the goals")
    options.add_argument("--markdown", action="store_true",
                         help="print the results as Markdown, for docs/benchmarks.md")
    return options
