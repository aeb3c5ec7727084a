"""Services on a mode's composites: they run while their mode runs, and stop when it is left."""

from __future__ import annotations

import time
from pathlib import Path

from cyborg.bt import Blackboard, ManualClock, TickLoop
from cyborg.modes import load_machine
from tests.bt.service_helpers import LOG, probe_registry
from tests.builders import N, project_json, registry, tree_json
from tests.modes.machines import write_modes

MODES = """\
project = "mission.b3.json"
initial = "normal"

[modes.normal]
tree = "patrol"

[modes.demo]
tree = "demo"

[[transitions]]
from = "normal"
to = "demo"
on_request = true
"""


def test_a_modes_services_run_between_ticks_and_stop_once_when_the_mode_is_left(
        tmp_path: Path) -> None:
    patrol = N("Sequence", N("Runner"), id="seq", services="Probe(interval=0.25)")
    trees = [tree_json(patrol, tree_id="patrol", title="patrol"),
             tree_json(N("Runner"), tree_id="demo", title="demo")]
    (tmp_path / "mission.b3.json").write_text(project_json(trees))
    clock = ManualClock()
    machine = load_machine(write_modes(tmp_path, MODES), registry=registry(), clock=clock,
                           services=probe_registry(), blackboard=Blackboard(resources={LOG: []}))
    log: list[tuple[str, str, str, float]] = machine.blackboard.resources[LOG]
    machine.tick()
    services = machine.services
    assert services is not None
    assert [event[:2] for event in log] == [("on_activate", "seq")]
    for _ in range(4):
        clock.advance(0.25)
        services.run_due(clock.now())
    runs = [event for event in log if event[0] == "run"]
    assert len(runs) == 4 and {event[1] for event in runs} == {"seq"}
    assert machine.request("demo", "a visitor")
    machine.tick()
    assert machine.mode == "demo" and machine.services is None
    assert [event[1] for event in log if event[0] == "on_deactivate"] == ["seq"]
    clock.advance(5.0)
    machine.tick()
    assert [event for event in log if event[0] == "run"] == runs
    assert [event[1] for event in log if event[0] == "on_deactivate"] == ["seq"]


def test_the_tick_loop_runs_a_modes_services_between_its_ticks(tmp_path: Path) -> None:
    patrol = N("Sequence", N("Runner"), id="seq", services="Probe(interval=0.1)")
    trees = [tree_json(patrol, tree_id="patrol", title="patrol"),
             tree_json(N("Runner"), tree_id="demo", title="demo")]
    (tmp_path / "mission.b3.json").write_text(project_json(trees))
    clock = ManualClock()
    machine = load_machine(write_modes(tmp_path, MODES), registry=registry(), clock=clock,
                           services=probe_registry(), blackboard=Blackboard(resources={LOG: []}))
    loop = TickLoop(machine, rate_hz=1.0)
    ticks: list[float] = []
    loop.add_listener(lambda snapshot: ticks.append(snapshot.time))
    loop.start()
    try:
        deadline = time.monotonic() + 30
        while len(ticks) < 3 and time.monotonic() < deadline:
            time.sleep(0.01)
    finally:
        loop.stop()
    runs = [event for event in machine.blackboard.resources[LOG] if event[0] == "run"]
    assert len(ticks) >= 3
    assert len(runs) >= 10 * (len(ticks) - 2)  # ten runs a tick period, on the tree's clock
