"""The cost of modes: a mode switch, and the mode machine's share of every tick.

    python3 -m benchmarks.modes [--quick] [--markdown]

Runs the bundled mission (``cyborg up``'s ``campus.modes.toml`` over ``campus_mission.b3.json``:
Patrol, Go charge, Stop and call, Demo) on a :class:`~cyborg.bt.ManualClock` against a robot
stub whose every answer is immediate — a move never ends by itself, and its ``cancel`` only
sets a flag — so what is timed is the engine's work, not the robot's:

* **mode switch**: ``machine.force(next)`` then ``machine.tick()``: the left tree's halt (a
  running MoveTo cancels its goal: the stub's cancel, instantaneous) and the entered tree's
  fresh start and first tick — what a transition costs between two ticks. The modes go round
  normal → low_battery → critical → demo → normal, each tree ticked a few times (untimed)
  before it is left, so it is RUNNING with a move under way. Goal: at most 1 ms, to which the
  halted actions' own cancel time adds (a BusRobot's cancel is sent in the background).
* **tick overhead**: ticking the machine in ``normal`` (its tree, then the conditions that may
  leave the mode: ``battery.percent < 10`` and ``< 30``) against ticking the same tree alone.

Each switch is timed with ``time.perf_counter_ns`` (median and 99th percentile of many);
ticks in batches with ``time.thread_time_ns`` (this thread's CPU only), the garbage
collector off, the median batch reported.
"""

from __future__ import annotations

import argparse
import gc
import math
import platform
import statistics
import sys
import time
from concurrent.futures import Future
from pathlib import Path

from benchmarks import benchmark_options
from benchmarks.results_table import print_results
from cyborg.app.up import CAMPUS_MODES, DATA
from cyborg.bt import Blackboard, ManualClock, Tree
from cyborg.modes import ModeMachine, load_machine
from cyborg.nav.geometry import Pose2D
from cyborg.robot.perceiving import SeenObject
from cyborg.robot.protocol import ROBOT, BatteryReading, DockState, Goal, MoveOutcome

SWITCH_GOAL_MS = 1.0
"""A mode switch (halt + first tick of the next tree) should take at most this long."""
CYCLE = ("low_battery", "critical", "demo", "normal")
"""The modes the switches go round, from normal."""


class StubMove:
    """A move that runs until cancelled; cancelling is setting a flag (and counting it)."""

    message = ""
    remaining = 10.0
    waiting = False
    """Never standing and waiting for people to make way."""

    def __init__(self, robot: StubRobot) -> None:
        self.robot = robot
        self.outcome: MoveOutcome | None = None

    @property
    def done(self) -> bool:
        """Whether the move has ended: once cancelled."""
        return self.outcome is not None

    def cancel(self) -> None:
        """Ends the move at once."""
        if self.outcome is None:
            self.robot.cancels += 1
        self.outcome = MoveOutcome.CANCELED


class StubRobot:
    """A robot that answers everything at once, with a battery at 50 % (no condition fires)."""

    def __init__(self) -> None:
        self.pose: Pose2D | None = Pose2D(0.0, 0.0)
        self.battery: BatteryReading | None = BatteryReading(50.0, False, DockState.UNDOCKED)
        names = ["Lecture hall", "Library", "Courtyard", "Cafeteria", "Workshop", "Office",
                 "Charger"]
        self._goals = {name: Goal(name, Pose2D(10.0 * i, 5.0)) for i, name in enumerate(names)}
        self.cancels = 0

    def goals(self, refresh: bool = False) -> dict[str, Goal]:
        """The campus goals."""
        return self._goals

    def move_to(self, goal: str) -> StubMove:
        """A move that never arrives."""
        return StubMove(self)

    def dock(self) -> tuple[bool, str]:
        """Accepted."""
        return True, "docking"

    def undock(self) -> tuple[bool, str]:
        """Accepted."""
        return True, "undocking"

    def stop(self) -> None:
        """Nothing to stop."""

    def distance_to(self, goal: Pose2D) -> Future[float]:
        """Straight-line distance, answered at once."""
        future: Future[float] = Future()
        future.set_result(math.dist((0.0, 0.0), (goal.x, goal.y)))
        return future

    def closest_goal(self) -> Future[tuple[str, float]]:
        """The first goal, answered at once."""
        future: Future[tuple[str, float]] = Future()
        future.set_result(("Lecture hall", 0.0))
        return future

    def call_for_help(self, reason: str, time: float) -> None:
        """Heard by nobody."""

    def objects(self) -> list[SeenObject]:
        """Nobody in sight: the patrol's greeting never begins."""
        return []

    def say(self, text: str) -> None:
        """Heard by nobody."""

    def drive(self, linear: float, angular: float) -> None:
        """Nothing to drive."""


def bundled_machine() -> ModeMachine:
    """The bundled mission's machine, on a manual clock, acting on a :class:`StubRobot`."""
    return load_machine(Path(str(DATA.joinpath(CAMPUS_MODES))), clock=ManualClock(),
                        blackboard=Blackboard(resources={ROBOT: StubRobot()}))


def settle(machine: ModeMachine, ticks: int = 3) -> None:
    """Ticks the current mode's tree a few times, 0.1 s apart: RUNNING, a move under way."""
    clock = machine.clock
    assert isinstance(clock, ManualClock)
    for _ in range(ticks):
        clock.advance(0.1)
        machine.tick()


def time_switches(machine: ModeMachine, count: int) -> list[float]:
    """Seconds each of ``count`` switches took (force + the entered tree's first tick)."""
    settle(machine)
    took: list[float] = []
    gc.disable()
    try:
        for number in range(count):
            target = CYCLE[number % len(CYCLE)]
            start = time.perf_counter_ns()
            decision = machine.force(target, "benchmark")
            machine.tick()
            took.append((time.perf_counter_ns() - start) * 1e-9)
            assert decision.accepted and machine.mode == target, decision.message
            settle(machine)
    finally:
        gc.enable()
    return took


def per_tick(tick: object, batch: int, repeats: int) -> float:
    """Median CPU seconds of one call of ``tick`` over ``repeats`` batches of ``batch``."""
    assert callable(tick)
    results: list[float] = []
    gc.disable()
    try:
        for _ in range(repeats):
            start = time.thread_time_ns()
            for _ in range(batch):
                tick()
            results.append((time.thread_time_ns() - start) * 1e-9 / batch)
    finally:
        gc.enable()
    return statistics.median(results)


def tick_costs(batch: int, repeats: int) -> tuple[float, float]:
    """``(machine, tree alone)``: seconds per tick of the normal mode's patrol, running."""
    machine = bundled_machine()
    settle(machine)
    tree: Tree = machine.tree
    assert machine.mode == "normal" and tree.running, "the patrol runs"
    machine_tick, tree_tick = [], []
    for _ in range(3):  # round-robin, so a slow spell hits both alike
        machine_tick.append(per_tick(machine.tick, batch, repeats))
        tree_tick.append(per_tick(tree.tick, batch, repeats))
    assert machine.mode == "normal", "no condition fired"
    return statistics.median(machine_tick), statistics.median(tree_tick)


def percentile(values: list[float], fraction: float) -> float:
    """The value below which ``fraction`` of ``values`` lie (nearest rank)."""
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, math.ceil(fraction * len(ordered)) - 1)]


def parser() -> argparse.ArgumentParser:
    """The benchmark's options."""
    return benchmark_options(__doc__, quick="400 switches, short batches")


def main(argv: list[str] | None = None) -> int:
    """Runs both measures and prints them (``--markdown``: for docs/benchmarks.md)."""
    args = parser().parse_args(argv)
    switches = 400 if args.quick else 4000
    batch, repeats = (200, 3) if args.quick else (2000, 7)

    machine = bundled_machine()
    took = time_switches(machine, switches)
    robot = machine.blackboard.resources[ROBOT]
    assert robot.cancels >= switches // 2, "the switches halted running moves"
    median, p99 = statistics.median(took), percentile(took, 0.99)
    with_machine, alone = tick_costs(batch, repeats)
    overhead = with_machine - alone
    rows = [
        ("mode switch, median", f"{median * 1e6:.0f} µs", f"{median * 1e3 / SWITCH_GOAL_MS:.2f}x"
         " goal", f"≤ {SWITCH_GOAL_MS:g} ms + the cancel's own time"),
        ("mode switch, p99", f"{p99 * 1e6:.0f} µs", f"{p99 * 1e3 / SWITCH_GOAL_MS:.2f}x goal",
         f"≤ {SWITCH_GOAL_MS:g} ms"),
        ("tick of the patrol, tree alone", f"{alone * 1e6:.1f} µs", "", ""),
        ("tick of the patrol, by the machine", f"{with_machine * 1e6:.1f} µs",
         f"{with_machine / alone:.2f}x", ""),
        ("machine's share of a tick", f"{overhead * 1e6:.1f} µs", "", "two conditions tried"),
    ]
    header = (f"{switches} switches round {' → '.join(('normal', *CYCLE))} "
              f"({robot.cancels} moves cancelled, at once); Python {platform.python_version()} on "
              f"{platform.machine()}")
    print_results(header, rows, markdown=args.markdown, widths=(36, 10, 12))
    return 0 if p99 <= SWITCH_GOAL_MS * 1e-3 or args.quick else 1


if __name__ == "__main__":
    sys.exit(main())
