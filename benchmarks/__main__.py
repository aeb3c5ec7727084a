"""Every benchmark's quick variant: ``python3 -m benchmarks --quick``.

    python3 -m benchmarks                         # the benchmarks and what each measures
    python3 -m benchmarks --quick                 # every quick variant, two at a time
    python3 -m benchmarks --quick sim_nav modes   # some of them
    python3 -m benchmarks --quick --jobs 1        # one at a time

Each quick variant runs in a process of its own (``python3 -m benchmarks.NAME --quick``), two at
a time by default (``--jobs``): a quick variant is a smoke test, not a measurement, so sharing
the machine does not matter. Each one's output is shown, whole, when it ends; then one line per
benchmark gives its exit status, its wall time and its CPU time (user and system, its own child
processes included: on a shared machine the wall time also counts the waits for a core). One
still running after ``--timeout`` seconds (300) is stopped. Exits 1 when any of them failed,
naming it. Full runs are long (the soak takes an hour) and are run one by one, as
docs/benchmarks.md gives them.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import threading
import time
from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

from benchmarks import BENCHMARKS

ROOT = Path(__file__).resolve().parents[1]


@dataclass(frozen=True)
class QuickRun:
    """How one quick variant went."""

    name: str
    status: int
    """Its exit status: 0 when it ran (a quick variant does not judge its goals)."""
    seconds: float
    """Wall-clock seconds."""
    cpu: float
    """CPU seconds, user and system, of its process and the processes it waited for."""


def parser() -> argparse.ArgumentParser:
    """The command's options."""
    options = argparse.ArgumentParser(prog="python3 -m benchmarks",
                                      description=(__doc__ or "").splitlines()[0])
    options.add_argument("--quick", action="store_true",
                         help="run the quick variants (without it: list the benchmarks)")
    options.add_argument("--jobs", type=int, default=2, metavar="N",
                         help="quick variants run at the same time (default 2)")
    options.add_argument("--timeout", type=float, default=300.0, metavar="S",
                         help="a quick variant still running after S seconds is stopped and "
                              "counts as failed (default 300)")
    options.add_argument("names", nargs="*", metavar="NAME",
                         help="only these benchmarks (default: all)")
    return options


def run_one(name: str, timeout: float, printing: threading.Lock) -> QuickRun:
    """Runs ``python3 -m benchmarks.NAME --quick``; prints its output when it ends.

    After ``timeout`` seconds the process is killed (its exit status then is -9).
    """
    started = time.monotonic()
    process = subprocess.Popen([sys.executable, "-m", f"benchmarks.{name}", "--quick"],
                               cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                               text=True, errors="replace")
    assert process.stdout is not None
    watchdog = threading.Timer(timeout, process.kill)
    watchdog.start()
    output = process.stdout.read()
    process.stdout.close()
    _pid, wait_status, usage = os.wait4(process.pid, 0)  # its CPU, its own children included
    watchdog.cancel()
    process.returncode = os.waitstatus_to_exitcode(wait_status)
    if process.returncode == -9:
        output += f"\nstopped after {timeout:g} s (--timeout)\n"
    with printing:
        print(f"== python3 -m benchmarks.{name} --quick\n{output}", flush=True)
    return QuickRun(name, process.returncode, time.monotonic() - started,
                    usage.ru_utime + usage.ru_stime)


def run_quick(names: Sequence[str], jobs: int, timeout: float) -> list[QuickRun]:
    """Runs the quick variants of ``names``, ``jobs`` at a time; in the order of ``names``."""
    printing = threading.Lock()
    with ThreadPoolExecutor(max_workers=max(1, jobs)) as pool:
        return list(pool.map(lambda name: run_one(name, timeout, printing), names))


def main(argv: Sequence[str] | None = None) -> int:
    options = parser()
    args = options.parse_args(argv)
    unknown = [name for name in args.names if name not in BENCHMARKS]
    if unknown:
        options.error(f"no benchmark {', '.join(unknown)} (there are: {', '.join(BENCHMARKS)})")
    names = args.names or list(BENCHMARKS)
    if not args.quick:
        for name in names:
            print(f"python3 -m benchmarks.{name:20} {BENCHMARKS[name]}")
        print("\npython3 -m benchmarks --quick runs every quick variant; docs/benchmarks.md "
              "gives each full run's command and figures")
        return 0
    started = time.monotonic()
    runs = run_quick(names, args.jobs, args.timeout)
    for run in runs:
        print(f"{run.name:20} {'ok' if run.status == 0 else f'FAILED (exit {run.status})':16} "
              f"{run.seconds:5.1f} s, CPU {run.cpu:5.1f} s")
    failed = [run.name for run in runs if run.status != 0]
    print(f"{len(runs)} quick variants, {args.jobs} at a time, in "
          f"{time.monotonic() - started:.0f} s (CPU {sum(run.cpu for run in runs):.0f} s; load "
          f"average {os.getloadavg()[0]:.1f})"
          + (f"; FAILED: {', '.join(failed)}" if failed else ""))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
