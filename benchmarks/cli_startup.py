"""The command line's start-up: time and peak memory of three commands against ``import zenoh``.

    python3 -m benchmarks.cli_startup [--quick] [--markdown] [--rounds N]

Each command runs in a fresh process, as a user types it, ``--rounds`` times in turn with the
baseline, a bare interpreter importing the bus's transport (``python3 -c "import zenoh"``):

* ``cyborg --help`` (goal: at most 0.3 s and 60 MiB): lists the commands
  (:mod:`cyborg.app.command_table`) and imports no command module;
* ``cyborg bt validate FILE`` on the shared patrol tree (goal: at most 0.6 s);
* ``cyborg topic list`` (joins the bus, lists what is there: nothing on an isolated bus).

Wall time is from the process's start to its end (median of the rounds); peak memory is the
process's maximum resident set (``ru_maxrss`` of the child). A busy machine stretches every
figure alike: the ratios to the baseline of the same rounds say more than the seconds.
"""

from __future__ import annotations

import argparse
import os
import socket
import statistics
import subprocess
import sys
import time
from collections.abc import Sequence

from benchmarks import SHARED, benchmark_options
from benchmarks.results_table import print_results

HELP_GOAL = (0.3, 60.0)
"""``cyborg --help``: at most this many seconds and MiB."""
VALIDATE_GOAL = 0.6
"""``cyborg bt validate FILE``: at most this many seconds."""
TREE = SHARED / "trees" / "patrol_recharge.b3.json"


def parser() -> argparse.ArgumentParser:
    """The command's options."""
    options = benchmark_options(__doc__, quick="one round")
    options.add_argument("--rounds", type=int, default=7, metavar="N",
                         help="runs of each command (default 7)")
    return options


def measure(argv: Sequence[str]) -> tuple[float, float]:
    """Wall seconds and peak MiB of one run of ``argv``, peak read from ``wait4``."""
    started = time.perf_counter()
    process = subprocess.Popen(argv, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    assert process.stderr is not None
    error = process.stderr.read()
    _, status, usage = os.wait4(process.pid, 0)
    seconds = time.perf_counter() - started
    process.returncode = os.waitstatus_to_exitcode(status)
    if process.returncode != 0:
        raise RuntimeError(f"{' '.join(argv)} exited {process.returncode}: "
                           f"{error.decode(errors='replace')[-500:]}")
    return seconds, usage.ru_maxrss / 1024


def main(argv: Sequence[str] | None = None) -> int:
    """Runs the benchmark; exits 1 when a goal is missed (never with ``--quick``)."""
    args = parser().parse_args(argv)
    python = sys.executable
    with socket.socket() as probe:  # a router of our own for `topic list` to join
        probe.bind(("127.0.0.1", 0))
        endpoint = f"tcp/127.0.0.1:{probe.getsockname()[1]}"
    commands = {
        "python3 -c 'import zenoh' (baseline)": [python, "-c", "import zenoh"],
        "cyborg --help": [python, "-m", "cyborg", "--help"],
        "cyborg bt validate FILE": [python, "-m", "cyborg", "bt", "validate", str(TREE)],
        "cyborg topic list": [python, "-m", "cyborg", "topic", "list", "--connect", endpoint,
                              "--wait", "0"],
    }
    router = subprocess.Popen([python, "-m", "cyborg", "router", "--listen", endpoint],
                              stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        assert router.stdout is not None
        router.stdout.readline()  # it says where it listens once it does
        return _run(args, commands, 1 if args.quick else max(1, args.rounds))
    finally:
        router.terminate()
        router.wait(10)


def _run(args: argparse.Namespace, commands: dict[str, list[str]], rounds: int) -> int:
    """Runs ``commands`` for ``rounds`` rounds and prints the table; the exit status."""
    times: dict[str, list[float]] = {name: [] for name in commands}
    peaks: dict[str, list[float]] = {name: [] for name in commands}
    for _ in range(rounds):
        for name, command in commands.items():  # in turn, so load changes hit all alike
            seconds, peak = measure(command)
            times[name].append(seconds)
            peaks[name].append(peak)
    baseline = statistics.median(times["python3 -c 'import zenoh' (baseline)"])
    rows = []
    goals = {"cyborg --help": f"<= {HELP_GOAL[0]:g} s, <= {HELP_GOAL[1]:g} MiB",
             "cyborg bt validate FILE": f"<= {VALIDATE_GOAL:g} s"}
    met = True
    for name in commands:
        wall, peak = statistics.median(times[name]), max(peaks[name])
        goal = goals.get(name, "")
        missed = {"cyborg --help": wall > HELP_GOAL[0] or peak > HELP_GOAL[1],
                  "cyborg bt validate FILE": wall > VALIDATE_GOAL}.get(name, False)
        if goal:
            goal += ": MISSES" if missed else ": meets"
        met = met and not missed
        rows.append((name, f"{wall:.3f} s, {peak:.0f} MiB", f"{wall / baseline:.2f}x", goal))
    load = os.getloadavg()[0]
    header = (f"Start-up of the command line, median of {rounds} round(s), peak memory the "
              f"largest (load average {load:.1f} on {os.cpu_count()} CPUs; "
              f"{time.strftime('%Y-%m-%d')})")
    print_results(header, rows, markdown=args.markdown, widths=(38, 18, 8))
    return 0 if met or args.quick else 1


if __name__ == "__main__":
    sys.exit(main())
