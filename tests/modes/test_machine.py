"""The mode machine: conditions, events, requests, force, hold, dwell, timeouts, halting."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import pytest

from cyborg.bt import RUNNING, Blackboard, ManualClock, TickLoop
from cyborg.modes import ModeFileError, ModeMachine, Transition, Trigger, load_machine
from tests.builders import registry
from tests.modes.machines import events, machine, write_modes, write_project

TREES = {"patrol": "R", "charge": "R", "critical": "R", "demo": "R"}
MISSION = """\
project = "mission.b3.json"
initial = "normal"
[modes.normal]
tree = "patrol"
[modes.low]
tree = "charge"
[modes.critical]
tree = "critical"
[modes.demo]
tree = "demo"
max_time = 30
then = "normal"

[[transitions]]
from = "*"
to = "critical"
when = "battery.percent < 5"
reason = "battery critical"
[[transitions]]
from = "normal"
to = "low"
when = "battery.percent < 20"
[[transitions]]
from = "low"
to = "normal"
when = "battery.percent >= 95"
[[transitions]]
from = "critical"
to = "normal"
event = "help_arrived"
[[transitions]]
from = ["normal", "low"]
to = "demo"
on_request = true
guard = "!busy"
"""


@pytest.fixture
def clock() -> ManualClock:
    return ManualClock()


def mission(tmp_path: Path, clock: ManualClock, text: str = MISSION) -> ModeMachine:
    return machine(tmp_path, text, TREES, clock)


def test_a_condition_leaves_the_mode_and_halts_its_tree_before_the_next_tick(
        tmp_path: Path, clock: ManualClock) -> None:
    m = mission(tmp_path, clock)
    seen: list[Transition] = []
    m.add_listener(seen.append)
    m.tick()
    assert m.mode == "normal" and events(m) == [("start", "patrol"), ("tick", "patrol")]
    m.globals["battery"] = {"percent": 15}
    clock.advance(1.0)
    m.tick()
    assert m.last is not None and m.last.mode == "normal"  # the tick was normal's
    assert m.mode == "low" and m.last.transition == seen[0]
    assert seen == [Transition("normal", "low", "when battery.percent < 20", 1.0,
                               Trigger.CONDITION, 2)]
    assert events(m) == [("tick", "patrol"), ("halt", "patrol")]
    assert not [n for n in m.trees["normal"].nodes if n.status is RUNNING]
    m.tick()
    assert m.last.mode == "low" and events(m) == [("start", "charge"), ("tick", "charge")]
    assert list(m.history) == seen and m.transition_count == 1


def test_the_order_of_the_file_decides_and_reasons_are_kept(tmp_path: Path,
                                                            clock: ManualClock) -> None:
    m = mission(tmp_path, clock)
    m.globals["battery"] = {"percent": 3}  # both transition 1 and 2 hold: 1 comes first
    m.tick()
    assert m.mode == "critical"
    assert m.history[-1].reason == "battery critical" and m.history[-1].number == 1
    m.tick()
    assert m.mode == "critical"  # '*' never leads from a mode to itself


def test_a_condition_that_cannot_be_evaluated_is_false(tmp_path: Path,
                                                       clock: ManualClock) -> None:
    m = mission(tmp_path, clock)
    m.tick()  # nothing wrote 'battery' yet: undefined < 5 cannot be compared
    assert m.mode == "normal"
    first = m.spec.transitions[0].when
    assert first is not None and "of 'battery' (undefined)" in (first.last_error or "")


@dataclass
class Battery:
    percent: float

    def recharge(self) -> None:
        raise AssertionError("a condition never calls methods")


def test_conditions_read_attributes_of_objects_but_not_methods(tmp_path: Path,
                                                               clock: ManualClock) -> None:
    m = mission(tmp_path, clock, MISSION.replace('"!busy"', '"!battery.recharge"'))
    m.globals["battery"] = Battery(12.0)
    m.tick()
    assert m.mode == "low"
    assert m.request("demo").accepted  # the guard reads recharge as undefined: !undefined


def test_events_are_taken_only_where_a_transition_leaves_the_mode(tmp_path: Path,
                                                                  clock: ManualClock) -> None:
    m = mission(tmp_path, clock)
    refused = m.fire_event("help_arrived")
    assert not refused.accepted and "in mode 'normal'" in refused.message
    assert not m.fire_event("nobody_listens").accepted
    m.globals["battery"] = {"percent": 3}
    m.tick()
    m.globals["battery"] = {"percent": 50}
    taken = m.fire_event("help_arrived")
    assert taken.accepted and m.mode == "normal"
    assert taken.transition is not None and taken.transition.trigger is Trigger.EVENT
    assert taken.transition.reason == "event help_arrived"


def test_requests_need_an_on_request_transition_and_its_guard(tmp_path: Path,
                                                              clock: ManualClock) -> None:
    m = mission(tmp_path, clock)
    m.tick()
    m.globals["busy"] = True
    refused = m.request("demo", "visitor")
    assert not refused.accepted and "guard '!busy' is false" in refused.message
    m.globals["busy"] = False
    taken = m.request("demo", "visitor")
    assert taken.accepted and m.mode == "demo" and m.history[-1].reason == "visitor"
    assert m.request("demo").message == "already in mode 'demo'"
    refused = m.request("low")
    assert not refused.accepted and "no request may leave it" in refused.message
    assert "there is no mode 'dmeo'" in m.request("dmeo").message


def test_force_goes_anywhere_past_guards_dwell_and_hold(tmp_path: Path,
                                                       clock: ManualClock) -> None:
    m = mission(tmp_path, clock, "min_dwell = 10\n" + MISSION)
    m.tick()
    m.hold(True)
    decision = m.force("critical", "operator saw smoke")
    assert decision.accepted and m.mode == "critical" and m.held  # the hold stays on
    assert decision.transition is not None and decision.transition.trigger is Trigger.FORCE
    assert events(m)[-1] == ("halt", "patrol")
    assert not m.force("nowhere").accepted


def test_dwell_holds_back_conditions_events_and_requests_not_timeouts(
        tmp_path: Path, clock: ManualClock) -> None:
    text = MISSION.replace("max_time = 30", "max_time = 3\nmin_dwell = 5")
    m = mission(tmp_path, clock, "min_dwell = 2.0\n" + text)
    m.tick()
    m.globals["battery"] = {"percent": 15}
    clock.advance(1.9)
    m.tick()
    assert m.mode == "normal"
    refused = m.request("demo")
    assert not refused.accepted and "minimum 2 s (min_dwell)" in refused.message
    clock.advance(0.1)
    m.tick()
    assert m.mode == "low"
    clock.advance(2.0)
    assert m.request("demo").accepted
    clock.advance(3.0)  # demo's own dwell (5 s) is longer than its max_time (3 s)
    m.tick()
    assert m.mode == "normal" and m.history[-1].trigger is Trigger.TIMEOUT


def test_hold_blocks_everything_but_force_until_released(tmp_path: Path,
                                                         clock: ManualClock) -> None:
    m = mission(tmp_path, clock)
    assert m.request("demo").accepted
    m.hold(True)
    m.globals["battery"] = {"percent": 3}
    clock.advance(60.0)
    m.tick()
    assert m.mode == "demo"  # neither the condition nor max_time
    refused = m.request("normal")
    assert not refused.accepted
    m.hold(False)
    m.tick()
    assert m.mode == "critical"


def test_a_mode_starts_fresh_and_only_the_global_scope_is_shared(tmp_path: Path,
                                                                 clock: ManualClock) -> None:
    scripts = dict(TREES, patrol="SR")  # the first tick succeeds, then RUNNING
    m = machine(tmp_path, MISSION, scripts, clock)
    normal, low = m.trees["normal"], m.trees["low"]
    assert normal.blackboard.globals is low.blackboard.globals
    assert normal.blackboard.trees is not low.blackboard.trees
    m.tick()
    m.tick()
    assert events(m)[-2:] == [("start", "patrol"), ("tick", "patrol")]  # its second step: R
    node_memory = [scope for scope in normal.blackboard.nodes.values() if scope]
    assert node_memory == [{"step": 2}]
    m.request("demo")
    m.force("normal")
    assert node_memory == [{}]  # emptied in place on entry
    m.tick()
    assert events(m)[-1:] == [("end:success", "patrol")]  # the script starts over: S


def test_a_tick_loop_runs_the_machine_and_halts_it_on_stop(tmp_path: Path,
                                                          clock: ManualClock) -> None:
    m = mission(tmp_path, clock)
    loop = TickLoop(m, rate_hz=10)
    modes: list[str] = []
    loop.add_listener(lambda snapshot: modes.append(m.last.mode if m.last else "?"))
    m.globals["battery"] = {"percent": 15}
    loop.run(max_ticks=3)
    assert modes == ["normal", "low", "low"] and clock.now() == pytest.approx(0.2)
    assert events(m)[-1] == ("halt", "charge")  # the loop's end halts the current tree


def test_a_listener_that_raises_is_logged_and_the_switch_completes(
        tmp_path: Path, clock: ManualClock, caplog: pytest.LogCaptureFixture) -> None:
    m = mission(tmp_path, clock)

    def broken(transition: Transition) -> None:
        raise RuntimeError("listener failed")

    m.add_listener(broken)
    assert m.force("demo").accepted and m.mode == "demo"
    assert "listener" in caplog.text and "listener failed" in caplog.text


def test_a_tree_that_does_not_build_stops_the_whole_machine(tmp_path: Path) -> None:
    write_project(tmp_path, TREES)
    path = tmp_path / "mission.b3.json"
    path.write_text(path.read_text().replace('"Scripted"', '"NoSuchNode"', 1))
    with pytest.raises(ModeFileError) as caught:
        load_machine(write_modes(tmp_path, MISSION), registry=registry(),
                     blackboard=Blackboard())
    text = str(caught.value)
    assert "mode 'normal': its tree 'patrol' does not load" in text
    assert "NoSuchNode" in text and str(path) in text


def test_the_machine_refuses_trees_that_share_no_global_scope(tmp_path: Path,
                                                              clock: ManualClock) -> None:
    m = mission(tmp_path, clock)
    trees = dict(m.trees)
    trees["low"].blackboard.globals = {}
    with pytest.raises(ValueError, match="one global scope"):
        ModeMachine(m.spec, trees)
    del trees["low"]
    with pytest.raises(ValueError, match="no tree given for the modes low"):
        ModeMachine(m.spec, trees)
