"""End to end: the shared patrol-and-recharge tree drives the simulated LX for a full battery cycle.

The tree (../shared/trees/patrol_recharge.b3.json) patrols room1, room2, Outside and room4 on
AMROffice.map; CheckBattery(25) takes over below 25 %: the robot abandons (and cancels) the move
in progress, drives to the Dock, charges to 95 % and patrols again. Everything runs in one
process on simulated time, as fast as the machine allows, from half a battery until the robot
has visited every goal again after charging (about 5.5 simulated hours; at most 13).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path

import pytest

from cyborg.app.cli import build_parser
from cyborg.app.launch import Launch
from cyborg.app.up import (
    CAMPUS_CHARGED,
    CAMPUS_DEMO_TIME,
    CAMPUS_MODES,
    CAMPUS_THRESHOLD,
    DATA,
    DEFAULT_SPEED,
    up_description,
    up_notes,
)
from cyborg.bt import SUCCESS
from cyborg.bt.snapshot import TickSnapshot
from cyborg.bus import BusConfig, Context
from cyborg.bus.actions import ActionServer, GoalStatus
from cyborg.modes import ModeMachine, read_mode_file
from cyborg.runner.component import RunningTree
from cyborg.sim.component import RunningSimulator
from cyborg.sim.simulator import Simulator
from tests.running_system import running_system, wait_in_simulated_time

HOURS = 13.0
"""At most this many simulated hours; the test ends once the robot patrols again after charging."""
START_CHARGE = 50.0
"""Percent: half a battery, so the threshold comes after a few hours of patrolling, not eight."""
PATROL = ["room1", "room2", "Outside", "room4"]


@dataclass
class Log:
    arrivals: list[tuple[float, str]] = field(default_factory=list)
    abandoned: list[tuple[float, str]] = field(default_factory=list)
    low_at: float | None = None
    min_charge: float = 100.0
    charged_at: float | None = None

    def tick(self, snapshot: TickSnapshot, labels: dict[str, str]) -> None:
        for uid, status in snapshot.visited:
            label = labels.get(uid, "")
            if status is SUCCESS and label.startswith("MoveTo "):
                self.arrivals.append((snapshot.time, label.removeprefix("MoveTo ")))
        for uid in snapshot.halted:
            label = labels.get(uid, "")
            if label.startswith(("MoveTo ", "Wait ")):
                self.abandoned.append((snapshot.time, label))

    def patrolled_again(self) -> bool:
        """Whether the robot, charged, has visited every goal of the patrol again."""
        charged = self.charged_at
        return charged is not None and set(PATROL) <= {
            name for at, name in self.arrivals if at > charged}

    def sensor(self, sim: Simulator) -> None:
        charge = sim.battery.charge_percent
        self.min_charge = min(self.min_charge, charge)
        if self.low_at is None and charge < 25.0:
            self.low_at = sim.time
        if self.low_at is not None and self.charged_at is None and charge >= 95.0:
            self.charged_at = sim.time


@pytest.mark.heavy
def test_patrol_and_recharge_over_a_full_battery_cycle(shared: Path) -> None:
    tree = shared / "trees" / "patrol_recharge.b3.json"
    amroffice = shared / "maps" / "AMROffice.map"
    log = Log()
    with running_system(amroffice, tree, speed=0, start="Dock", battery=START_CHARGE) as system:
        sim, runner = system.sim, system.runner
        labels = {node.uid: node.label for node in runner.tree}
        simulator = system._simulator()
        simulator.loop.on_sensor.append(log.sensor)
        runner.runner.add_listener(lambda snapshot: log.tick(snapshot, labels))
        started = time.monotonic()
        while sim.time < HOURS * 3600 and not log.patrolled_again():
            assert simulator.loop.running, f"the simulation stopped: {simulator.loop.error}"
            assert time.monotonic() - started < 1200, f"too slow: {sim.time / 3600:.1f} h"
            time.sleep(0.5)
        wall = time.monotonic() - started
        with simulator.loop.lock:
            bumps, docks, odometer = sim.base.bumps, sim.docking.docks, sim.base.odometer
            server = next(entity for entity in simulator.node._entities
                          if isinstance(entity, ActionServer))
            goals = list(server._goals.values())
    hours = sim.time / 3600
    print(f"\n{hours:.1f} h simulated in {wall:.0f} s ({hours * 3600 / wall:.0f}x real time): "
          f"{len(log.arrivals)} arrivals, {odometer / 1000:.1f} km, {docks} docking(s), "
          f"lowest charge {log.min_charge:.1f} %")

    # no collision, a real battery cycle: below the threshold, docked, charged, patrolling again
    assert bumps == 0
    assert log.low_at is not None and log.charged_at is not None, "no full battery cycle"
    assert docks >= 1 and log.min_charge > 20.0
    before = [name for at, name in log.arrivals if at < log.low_at]
    recharge = [name for at, name in log.arrivals if log.low_at <= at <= log.charged_at]
    after = [name for at, name in log.arrivals if at > log.charged_at]
    # patrols the goals in order (each arrival is the next goal of the round)
    for arrivals in (before, after):
        rounds = [name for name in arrivals if name != "Dock"]
        assert rounds == [PATROL[i % len(PATROL)] for i in range(len(rounds))], rounds[:12]
    assert len(before) >= 4 * len(PATROL), "several full rounds before the battery ran low"
    assert set(after) >= set(PATROL), "every goal visited again after charging"
    # going to the dock abandoned the move in progress, and that goal was cancelled
    assert recharge[:1] == ["Dock"]
    # (or the Wait between two moves, if the battery ran low just then)
    abandoned = [label for at, label in log.abandoned if log.low_at <= at <= log.low_at + 5.0]
    assert abandoned, log.abandoned[:5]
    if abandoned[0].startswith("MoveTo"):
        assert abandoned[0].removeprefix("MoveTo ") in PATROL
    assert any(goal.status is GoalStatus.CANCELED for goal in goals)
    # no goal left behind: every goal ended except the one being driven now
    assert sum(not goal.status.terminal for goal in goals) <= 1


# ---------------------------------------------------------------------------------- cyborg up
CYCLE_WITHIN = 180.0
"""Wall-clock seconds in which `cyborg up`, on its defaults, shows normal -> low_battery ->
normal (README, docs/modes.md)."""
FASTER = 4.0
"""How many times the default pace the test runs `cyborg up` at."""


def _bundled_condition(source: str, target: str) -> str:
    """The `when` of the bundled mode file's transition from ``source`` to ``target``."""
    spec = read_mode_file(Path(str(DATA.joinpath(CAMPUS_MODES))))
    (when,) = [t.when.source for t in spec.transitions
               if t.when is not None and source in t.sources and t.target == target]
    return when


def test_cyborg_up_runs_the_mission_on_modes_just_above_low_battery_and_says_so() -> None:
    args = build_parser().parse_args(["up", "--no-detector"])
    description = up_description(args)
    sim = next(spec for spec in description.nodes if spec.kind == "simulator")
    runner = next(spec for spec in description.nodes if spec.kind == "tree_runner")
    assert runner.parameters["tree_file"].endswith(CAMPUS_MODES)
    assert _bundled_condition("normal", "low_battery") == \
        f"battery.percent < {CAMPUS_THRESHOLD:g}"
    assert _bundled_condition("low_battery", "normal") == \
        f"battery.percent >= {CAMPUS_CHARGED:g}"
    spec = read_mode_file(Path(str(DATA.joinpath(CAMPUS_MODES))))
    assert spec.modes["demo"].max_time == CAMPUS_DEMO_TIME
    assert {"emergency", "help_arrived"} <= {t.event for t in spec.transitions}
    assert CAMPUS_THRESHOLD < sim.parameters["battery"] <= CAMPUS_THRESHOLD + 5, "low soon"
    assert sim.parameters["speed"] > 1, "faster than real time"
    notes = "\n".join(up_notes(args))
    assert f"{sim.parameters['speed']:g}x real time (--speed)" in notes
    assert f"battery at {sim.parameters['battery']:g} % (--battery)" in notes
    assert f"below {CAMPUS_THRESHOLD:g} %" in notes and f"to {CAMPUS_CHARGED:g} %" in notes
    assert "/cyborg/help" in notes and "`help_arrived`" in notes
    assert f"demo for {CAMPUS_DEMO_TIME / sim.parameters['speed']:g} s" in notes
    assert all(len(f"  {line}") < 80 for line in notes.splitlines()), "as printed"
    own = build_parser().parse_args(["up", "--speed", "1", "--battery", "100"])
    assert "low_battery" not in "\n".join(up_notes(own)), "no promise the user's choice breaks"
    plain = up_description(build_parser().parse_args(["up", "--tree", "x.b3.json"]))
    assert next(spec for spec in plain.nodes if spec.kind == "tree_runner").parameters[
        "tree_file"] == "x.b3.json", "--tree still runs a plain tree"


@pytest.mark.heavy
def test_cyborg_up_on_its_defaults_goes_to_charge_and_back_to_patrol_within_three_minutes(
) -> None:
    """What `cyborg up` starts, on its default charge (the monitor and camera left out): the
    patrol runs, the battery falls below the threshold, the mode machine sends the robot to
    charge, and once charged back to patrol, within the simulated time that the README's three
    minutes are at the default pace. It runs FASTER times the default pace, so the test takes
    a quarter of those minutes; the simulated times are the same at any pace."""
    args = build_parser().parse_args(["up", "--no-monitor", "--no-detector",
                                      "--speed", str(DEFAULT_SPEED * FASTER)])
    seen: list[str] = []
    with Context(BusConfig.isolated()) as context:
        launch = Launch(up_description(args), context)
        launch.start()
        try:
            sim = next(item for item in launch.running
                       if isinstance(item, RunningSimulator)).loop.simulator
            runner = next(item for item in launch.running if isinstance(item, RunningTree))
            machine = runner.runner.ticked
            assert isinstance(machine, ModeMachine)
            labels = {node.uid: node.label for tree in machine.trees.values() for node in tree}
            runner.runner.runner.add_listener(lambda snapshot: seen.extend(
                labels[uid] for uid in snapshot.active[-1:]))
            wait_in_simulated_time(lambda: machine.transition_count >= 2,
                                   lambda: sim.time, CYCLE_WITHIN * DEFAULT_SPEED,
                                   what="low_battery and back to normal")
            charged = sim.battery.charge_percent
        finally:
            launch.stop()
    first, second = machine.history[0], machine.history[1]
    assert (first.source, first.target, second.source, second.target) == (
        "normal", "low_battery", "low_battery", "normal")
    assert second.time <= CYCLE_WITHIN * DEFAULT_SPEED, \
        f"back to patrol after {second.time / DEFAULT_SPEED:.0f} s at the default pace"
    assert charged >= CAMPUS_CHARGED
    patrol = seen[:seen.index("MoveTo Charger")]
    assert {"MoveTo Lecture hall", "MoveTo Library"} <= set(patrol), "the patrol came first"
    assert "Charge to 60%" in seen
