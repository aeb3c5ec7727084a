"""Services on composites: when they start, run and stop, what they write, what they report."""

from __future__ import annotations

import json
import logging
from importlib.resources import files
from typing import Any

import jsonschema
import pytest

from cyborg.bt import RUNNING, SUCCESS, ManualClock, TickLoop, Tree, loads_tree
from tests.bt.service_helpers import LOG, advance, probe_registry, probe_tree, service_log
from tests.builders import N, registry, tree_json


def _events(tree: Tree) -> list[tuple[str, str, float]]:
    return [(event, composite, time) for event, composite, _name, time in service_log(tree)]


def test_a_service_starts_when_its_composite_becomes_running_and_stops_when_it_ends() -> None:
    spec = N("Sequence", N("Scripted", script="RRS"), id="seq", services="Probe(interval=0.5)")
    tree = probe_tree(spec)
    assert tree.tick().status is RUNNING
    assert _events(tree) == [("on_activate", "seq", 0.0)]
    advance(tree, 1.0)  # due at 0.5 and 1.0, between the ticks
    assert _events(tree) == [("run", "seq", 0.5), ("run", "seq", 1.0)]
    tree.tick()
    advance(tree, 0.25)
    assert tree.tick().status is SUCCESS
    assert _events(tree) == [("on_deactivate", "seq", 1.25)]
    advance(tree, 5.0)
    assert _events(tree) == [] and tree.services is not None
    assert tree.services.next_due() == float("inf")


def test_a_composite_that_completes_in_the_tick_it_started_never_activates_them() -> None:
    tree = probe_tree(N("Sequence", N("Succeeder"), services="Probe(run_on_activation=true)"))
    for _ in range(3):
        assert tree.tick().status is SUCCESS
        advance(tree, 1.0)
    assert _events(tree) == []


def test_run_on_activation_runs_once_right_after_on_activate_and_keeps_the_timer() -> None:
    spec = N("Sequence", N("Runner"), id="seq",
             services="Probe(interval=1, run_on_activation=true)")
    tree = probe_tree(spec)
    tree.tick()
    assert tree.blackboard["probe"] == 1  # fresh for the next tick's conditions
    advance(tree, 1.0)
    assert _events(tree) == [("on_activate", "seq", 0.0), ("run", "seq", 0.0),
                             ("run", "seq", 1.0)]


def test_services_run_before_the_tick_that_is_due_with_them() -> None:
    spec = N("Sequence", N("Runner"), id="seq", services="Probe(interval=1)")
    tree = probe_tree(spec)
    clock = tree.clock
    assert isinstance(clock, ManualClock)
    tree.tick()
    clock.advance(3.5)  # no loop ran them in between: the tick runs what is due, once
    tree.tick()
    assert _events(tree) == [("on_activate", "seq", 0.0), ("run", "seq", 3.5)]
    advance(tree, 1.0)  # late, so the next run is an interval after the late one
    assert _events(tree) == [("run", "seq", 4.5)]


def test_a_tick_loop_runs_a_fast_service_between_slow_ticks() -> None:
    clock = ManualClock()
    spec = N("Sequence", N("Runner"), id="seq", services="Probe(interval=0.1)")
    tree = probe_tree(spec, clock)
    loop = TickLoop(tree, rate_hz=1.0)
    loop.run(max_ticks=3)
    runs = [time for event, _, time in _events(tree) if event == "run"]
    assert len(runs) == 20  # 10 Hz for the two seconds between the three ticks
    assert runs == pytest.approx([0.1 * k for k in range(1, 21)])
    assert tree.services is not None and tree.services.active == []  # halted on the way out


def test_restart_on_activation_restarts_the_timer_unless_told_not_to() -> None:
    def runs_after_reentry(restart: bool) -> list[float]:
        spec = N("Priority", N("Scripted", script="FFS"),
                 N("Sequence", N("Scripted", script="RSR"), id="seq",
                   services=f"Probe(interval=1, restart_on_activation={str(restart).lower()})"))
        tree = probe_tree(spec)
        tree.tick()  # seq becomes RUNNING at 0, due at 1
        advance(tree, 0.75)
        tree.tick()  # seq succeeds at 0.75: stopped, 0.25 s before its run
        advance(tree, 0.5)
        tree.tick()  # the guard succeeds at 1.25
        tree.tick()  # seq ... not reached: the guard stays SUCCESS
        return [time for event, _, time in _events(tree) if event == "run"]

    assert runs_after_reentry(True) == [] == runs_after_reentry(False)

    def second_activation(restart: bool) -> list[tuple[str, str, float]]:
        spec = N("Sequence", N("Scripted", script="RSRSR"), id="seq",
                 services=f"Probe(interval=1, restart_on_activation={str(restart).lower()})")
        tree = probe_tree(spec)
        tree.tick()  # active at 0, due at 1
        advance(tree, 0.75)
        tree.tick()  # succeeds at 0.75
        advance(tree, 0.5)
        tree.tick()  # RUNNING again at 1.25
        advance(tree, 0.5)
        return _events(tree)

    assert second_activation(True)[-2:] == [("on_deactivate", "seq", 0.75),
                                            ("on_activate", "seq", 1.25)]
    kept = second_activation(False)
    # the due time 1.0 passed while inactive: it runs when the composite is active again
    assert kept[-2:] == [("on_activate", "seq", 1.25), ("run", "seq", 1.25)]


def test_the_deviation_is_seeded_bounded_and_differs_between_services() -> None:
    def runs() -> dict[str, list[float]]:
        spec = N("Sequence", N("Runner"), id="seq",
                 services="Probe(interval=1, deviation=0.4); OtherProbe(interval=1, "
                          "deviation=0.4)")
        tree = probe_tree(spec)
        tree.tick()
        advance(tree, 30.0)
        times: dict[str, list[float]] = {}
        for event, _composite, name, time in service_log(tree):
            if event == "run":
                times.setdefault(name, []).append(time)
        return times

    first, second = runs(), runs()
    assert first == second  # the same tree runs its services at the same times
    assert first["Probe"] != first["OtherProbe"]
    for times in first.values():
        gaps = [b - a for a, b in zip([0.0, *times], times, strict=False)]
        assert all(0.6 - 1e-9 <= gap <= 1.4 + 1e-9 for gap in gaps)
        assert max(gaps) - min(gaps) > 0.1  # it does deviate


def test_a_parent_switching_branches_stops_one_and_starts_the_other() -> None:
    spec = N("Priority",
             N("Sequence", N("Scripted", script="RF"), id="first", services="Probe"),
             N("Sequence", N("Runner"), id="second", services="Probe"), id="top")
    tree = probe_tree(spec)
    tree.tick()
    assert _events(tree) == [("on_activate", "first", 0.0)]
    tree.tick()
    assert _events(tree) == [("on_deactivate", "first", 0.0), ("on_activate", "second", 0.0)]
    assert tree.services is not None
    assert [node.uid for node in tree.services.active] == ["second"]


def test_nested_services_start_outermost_first_and_stop_innermost_first() -> None:
    spec = N("Sequence", N("Sequence", N("Runner"), id="inner", services="Probe"),
             id="outer", services="Probe")
    tree = probe_tree(spec)
    tree.tick()
    tree.halt()
    assert [(event, uid) for event, uid, _ in _events(tree)] == [
        ("on_activate", "outer"), ("on_activate", "inner"),
        ("on_deactivate", "inner"), ("on_deactivate", "outer")]
    assert tree.halt() == [] and _events(tree) == []


def test_stopping_or_reloading_a_tick_loop_stops_the_services_once() -> None:
    clock = ManualClock()
    tree = probe_tree(N("Sequence", N("Runner"), id="seq", services="Probe"), clock)
    loop = TickLoop(tree, rate_hz=10.0)
    loop.step()
    replacement = probe_tree(N("Sequence", N("Runner"), id="seq", services="Probe"), clock)
    loop.replace_tree(replacement)
    assert [event for event, _, _ in _events(tree)] == ["on_activate", "on_deactivate"]
    loop.step()
    loop.stop()
    assert [event for event, _, _ in _events(replacement)] == ["on_activate", "on_deactivate"]


def test_a_service_that_raises_is_reported_with_its_composite_and_stopped(
        caplog: pytest.LogCaptureFixture) -> None:
    spec = N("Sequence", N("Runner"), id="seq", title="Patrol",
             services="Probe(interval=1, fail=run); OtherProbe(interval=1)")
    tree = probe_tree(spec)
    tree.tick()
    with caplog.at_level(logging.ERROR, logger="cyborg.bt"):
        advance(tree, 3.0)
        tree.tick()
    assert tree.last is not None and tree.last.status is RUNNING  # the tree goes on
    events = [(event, name) for event, _, name, _ in service_log(tree)]
    assert events.count(("run", "Probe")) == 1 and ("on_deactivate", "Probe") in events
    assert events.count(("run", "OtherProbe")) == 3
    assert "service Probe on composite seq (Patrol, Sequence) raised in run" in caplog.text
    states = {state.service: state for state in tree.last.services or ()}
    assert states["Probe"].error == "RuntimeError: Probe told to fail in run"
    assert not states["Probe"].active and states["OtherProbe"].active
    tree.halt()  # the failed one is not stopped twice
    assert [(event, name) for event, _, name, _ in service_log(tree)] == [
        ("on_deactivate", "OtherProbe")]


def test_on_deactivate_follows_an_on_activate_that_raised() -> None:
    tree = probe_tree(N("Sequence", N("Runner"), id="seq",
                        services="Probe(fail=on_activate, run_on_activation=true)"))
    tree.tick()
    assert [event for event, _, _ in _events(tree)] == ["on_activate", "on_deactivate"]
    advance(tree, 5.0)
    tree.tick()
    assert _events(tree) == []


def test_snapshots_carry_what_each_service_wrote_and_when_it_ran() -> None:
    spec = N("Sequence", N("Runner"), id="seq", services="Probe(key=count, interval=2)")
    tree = probe_tree(spec)
    first = tree.tick()
    assert first.services is not None
    assert [state.to_json() for state in first.services] == [
        {"composite": "seq", "service": "Probe", "active": True, "last_run": None, "runs": 0,
         "wrote": {}, "error": None}]
    advance(tree, 4.0)
    data = tree.tick().to_json()
    assert data["services"] == [{"composite": "seq", "service": "Probe", "active": True,
                                 "last_run": 4.0, "runs": 2, "wrote": {"count": "2"},
                                 "error": None}]
    quiet = tree.tick()  # nothing changed: the same states, not rebuilt
    assert quiet.services is tree.last.services if tree.last else False


def test_trees_without_services_have_none_in_their_snapshots() -> None:
    tree = probe_tree(N("Sequence", N("Runner")))
    assert tree.services is None
    snapshot = tree.tick()
    assert snapshot.services is None and "services" not in snapshot.to_json()


def _schema() -> dict[str, Any]:
    schema: dict[str, Any] = json.loads(
        files("cyborg.bt").joinpath("structure.schema.json").read_text())
    return schema


def test_the_structure_names_each_composites_services() -> None:
    spec = N("Sequence", N("Parallel", N("Runner"), id="par",
                           services="Probe(interval=2, deviation=0.5); OtherProbe"),
             id="seq")
    structure = probe_tree(spec).structure.to_json()
    jsonschema.validate(structure, _schema())
    top = structure["root"]["children"][0]
    assert "services" not in top
    assert top["children"][0]["services"] == [
        {"name": "Probe", "declaration": "Probe(interval=2, deviation=0.5)", "interval": 2.0,
         "deviation": 0.5, "restart_on_activation": True, "run_on_activation": False},
        {"name": "OtherProbe", "declaration": "OtherProbe", "interval": 0.5,
         "deviation": 0.0, "restart_on_activation": True, "run_on_activation": False}]


def test_a_behavior3_v1_composite_carries_services_in_its_args() -> None:
    text = json.dumps({"name": "patrol", "root": {
        "id": 1, "name": "Sequence", "args": {"services": "Probe(interval=1)"},
        "children": [{"id": 2, "name": "Log", "args": {"message": "x"}},
                     {"id": 3, "name": "AlwaysRunning", "children": [
                         {"id": 4, "name": "Log", "args": {"message": "y"}}]}]}})
    tree = loads_tree(text, registry=registry(), clock=ManualClock(),
                      services=probe_registry())
    tree.blackboard.resources[LOG] = []
    tree.tick()
    advance(tree, 1.0)
    assert [(event, composite) for event, composite, _ in _events(tree)] == [
        ("on_activate", "1"), ("run", "1")]


def test_a_node_class_with_its_own_services_parameter_keeps_it() -> None:
    from cyborg.bt import Action, Status

    class Announce(Action):
        def __init__(self, services: str = "") -> None:
            self.services = services

        def tick(self) -> Status:
            return SUCCESS

    reg = registry()
    reg.add(Announce)
    text = json.dumps(tree_json(N("Sequence", N("Announce", services="taxi; bus")), reg=reg))
    tree = loads_tree(text, registry=reg, services=probe_registry())
    assert tree.services is None
    announce = next(node for node in tree if isinstance(node, Announce))
    assert announce.services == "taxi; bus"


def test_a_composite_halted_and_entered_again_in_one_tick_restarts_its_services() -> None:
    from cyborg.bt import Decorator, Status

    class Restart(Decorator):
        """Halts a RUNNING child and ticks it afresh, in the same tick."""

        def tick(self) -> Status:
            if self.child.status is RUNNING:
                self.child.halt()
            return self.child.execute()

    reg = registry()
    reg.add(Restart)
    spec = N("Restart", N("Sequence", N("Runner"), id="seq", services="Probe"))
    text = json.dumps(tree_json(spec, reg=reg))
    tree = loads_tree(text, registry=reg, clock=ManualClock(), services=probe_registry())
    tree.blackboard.resources[LOG] = []
    tree.tick()
    tree.tick()
    assert [event for event, _, _ in _events(tree)] == ["on_activate", "on_deactivate",
                                                         "on_activate"]


def test_a_timing_made_in_python_below_the_minimum_still_moves_time_on() -> None:
    from cyborg.bt.service_runner import ScheduledService
    from cyborg.bt.services import MIN_INTERVAL, ServiceTiming
    from tests.bt.service_helpers import Probe

    tree = probe_tree(N("Sequence", N("Runner"), id="seq"))
    probe = Probe()
    probe.name, probe.composite_uid = "Probe", "seq"
    probe.timing = ServiceTiming(interval=1e-300)
    scheduled = ScheduledService(probe, tree.by_uid["seq"], tree.blackboard, 0)
    tree.blackboard.resources[LOG] = []
    scheduled.activate(5.0)
    assert scheduled.due >= 5.0 + MIN_INTERVAL
    scheduled.run_if_due(scheduled.due)
    assert scheduled.due >= 5.0 + 2 * MIN_INTERVAL


def test_a_background_loop_on_the_wall_clock_runs_services_and_stops_promptly() -> None:
    import time

    from cyborg.bt import MonotonicClock

    tree = probe_tree(N("Sequence", N("Runner"), id="seq", services="Probe(interval=0.02)"))
    tree.clock = MonotonicClock()
    loop = TickLoop(tree, rate_hz=0.5)  # one tick, then a long sleep full of service runs
    loop.start()
    deadline = time.monotonic() + 30.0
    while tree.blackboard.get("probe", 0) < 3 and time.monotonic() < deadline:
        time.sleep(0.01)
    assert tree.blackboard.get("probe", 0) >= 3
    loop.stop(timeout=30.0)  # wakes the sleep between two service runs, halts the tree
    assert loop.stopped and tree.services is not None and tree.services.active == []
    assert [event for event, _, _ in _events(tree)][-1] == "on_deactivate"


def test_the_dot_export_names_a_composites_services_under_its_label() -> None:
    from cyborg.bt.dot import structure_to_dot

    tree = probe_tree(N("Sequence", N("Runner"), id="seq", title="Patrol",
                        services="Probe(interval=2); OtherProbe(interval=0.25)"))
    text = structure_to_dot(tree.structure.to_json())
    assert '"seq" [label="Patrol\\n\u27f3 Probe 2s, OtherProbe 0.25s"' in text
    structure = tree.structure.to_json()
    structure["root"]["children"][0]["services"] = [{"name": 3}, "junk"]
    assert '"seq" [label="Patrol",' in structure_to_dot(structure)
