"""Regressions: behavior3's defects, fixed in cyborg's stock nodes, and faults found since.

Each of behavior3's defects (stale nodes never closed, Limiter never limiting, MaxTime ticking
past its deadline, endless repeats spinning a tick forever, RepeatUntil* returning no status)
has a test that fails on behavior3's semantics; so have MemSequence restarting after a halt,
the halting order the property test found, and timing across a clock set back.
"""

from __future__ import annotations

import logging
from typing import Any

import pytest

from cyborg.bt import FAILURE, RUNNING, SUCCESS, ManualClock, Status
from tests.bt.node_helpers import ROOT, build, leaf, letters, parse_events, run
from tests.builders import N, events, tree_from


def test_regression_stale_node_replaced_by_sibling_at_same_depth_is_halted() -> None:
    """behavior3 defect 1: a RUNNING node replaced by a sibling at the same depth was never
    closed, and its next activation skipped open()."""
    tree = build(N("Priority", leaf("a", "FRF"), leaf("b", "R"), id="p"))

    first = tree.tick()
    assert first.active == [ROOT, "p", "b"]
    assert events(tree) == parse_events("a:start a:tick a:end:failure b:start b:tick")

    second = tree.tick()  # a (same depth) is now RUNNING instead of b
    assert second.active == [ROOT, "p", "a"]
    assert second.halted == ["b"]
    assert events(tree) == parse_events("a:start a:tick b:halt")
    assert tree.by_uid["b"].status is None

    third = tree.tick()  # b becomes active again: a fresh activation, so on_start again
    assert third.active == [ROOT, "p", "b"]
    assert third.halted == []  # a completed with FAILURE; it is not halted
    assert events(tree) == parse_events("a:tick a:end:failure b:start b:tick")


def test_regression_stale_subtree_replaced_at_same_depth_is_halted_deepest_first() -> None:
    spec = N("Priority",
             N("Sequence", leaf("a", "FRF"), id="s1"),
             N("Sequence", leaf("b", "R"), id="s2"),
             id="p")
    tree = build(spec)
    assert tree.tick().active == [ROOT, "p", "s2", "b"]
    events(tree)
    snapshot = tree.tick()
    assert snapshot.active == [ROOT, "p", "s1", "a"]
    assert snapshot.halted == ["b", "s2"]
    assert events(tree) == parse_events("a:start a:tick b:halt")
    snapshot = tree.tick()
    assert snapshot.active == [ROOT, "p", "s2", "b"]
    assert events(tree) == parse_events("a:tick a:end:failure b:start b:tick")


def test_regression_limiter_limits_across_activations() -> None:
    """behavior3 defect 5: Limiter reset its count on every open() and never limited."""
    spec = N("Repeater", N("Sequence", N("Limiter", leaf("a", "S"), id="l", maxLoop=2),
                           leaf("b", "S")), maxLoop=-1)
    tree = build(spec)
    snapshots = [tree.tick() for _ in range(5)]
    assert [snapshot.statuses["l"] for snapshot in snapshots] == [
        SUCCESS, SUCCESS, FAILURE, FAILURE, FAILURE]
    log = events(tree)
    assert log.count(("tick", "a")) == 2
    assert log.count(("tick", "b")) == 2


def test_regression_limiter_count_survives_halts() -> None:
    tree = build(N("Limiter", leaf("a", "RSR"), id="l", maxLoop=1))
    assert tree.tick().status is RUNNING
    tree.halt()  # a halt is not a completion
    assert tree.tick().status is SUCCESS
    assert tree.tick().status is FAILURE
    tree.halt()
    assert tree.tick().status is FAILURE
    assert events(tree) == parse_events("a:start a:tick a:halt a:start a:tick a:end:success")


def test_regression_maxtime_is_in_milliseconds_and_halts_without_ticking() -> None:
    """behavior3 defect 6: MaxTime ticked the child after the deadline and never halted it."""
    tree = build(N("MaxTime", leaf("a", "R"), id="m", maxTime=1000))
    statuses = [snapshot.status for snapshot in run(tree, [0, 0.5, 0.25])]
    assert statuses == [RUNNING, RUNNING, RUNNING]  # 750 ms < 1000 ms
    assert events(tree) == parse_events("a:start a:tick a:tick a:tick")
    (snapshot,) = run(tree, [0.25])  # 1000 ms: the deadline
    assert snapshot.status is FAILURE
    assert snapshot.visited == [("m", FAILURE), (ROOT, FAILURE)]  # the child is not ticked
    assert snapshot.halted == ["a"]
    assert events(tree) == parse_events("a:halt")
    assert tree.by_uid["a"].status is None


def test_regression_maxtime_with_nonzero_start_time() -> None:
    clock = ManualClock(100.0)
    tree = tree_from(N("MaxTime", leaf("a", "R"), maxTime=250), clock=clock)
    assert tree.tick().status is RUNNING
    clock.advance(0.125)
    assert tree.tick().status is RUNNING
    clock.advance(0.125)
    assert tree.tick().status is FAILURE
    assert events(tree) == parse_events("a:start a:tick a:tick a:halt")


@pytest.mark.parametrize(
    ("name", "child", "prop"),
    [("Repeater", "Succeeder", "maxLoop"), ("Repeater", "Failer", "maxLoop"),
     ("RepeatUntilFailure", "Succeeder", "maxLoop"),
     ("RepeatUntilSuccess", "Failer", "maxLoop"), ("Retry", "Failer", "maxAttempts")],
)
def test_regression_endless_repeat_over_instant_child_returns_each_tick(
        name: str, child: str, prop: str) -> None:
    """behavior3 defect 7: Repeater -1 over a child that completes at once spun forever."""
    props: dict[str, Any] = {prop: -1}
    tree = build(N(name, N(child, id="c"), id="r", **props))
    for _ in range(5):
        snapshot = tree.tick()
        assert snapshot.status is RUNNING
        assert [uid for uid, _ in snapshot.visited] == ["c", "r", ROOT]  # child ticked once


@pytest.mark.parametrize("name", ["RepeatUntilFailure", "RepeatUntilSuccess"])
@pytest.mark.parametrize("script", ["S", "F", "SF", "FS", "RS", "RF", "SSSF", "FFFS", "RRF"])
@pytest.mark.parametrize("max_loop", [-1, 1, 2, 3])
def test_regression_repeat_until_always_returns_a_status(
        name: str, script: str, max_loop: int, caplog: pytest.LogCaptureFixture) -> None:
    """behavior3 defect 8: RepeatUntil* could return an unbound (None) status."""
    tree = build(N(name, leaf("a", script), id="r", maxLoop=max_loop))
    with caplog.at_level(logging.ERROR, logger="cyborg.bt"):
        for _ in range(6):
            snapshot = tree.tick()
            status = snapshot.statuses["r"]
            assert isinstance(status, Status)
            assert status in (SUCCESS, FAILURE, RUNNING)
    assert caplog.records == []
    assert tree.by_uid["r"].last_error is None


@pytest.mark.parametrize(
    ("name", "script", "max_loop", "expected"),
    [("RepeatUntilFailure", "SSF", -1, "RRF"), ("RepeatUntilFailure", "S", 3, "RRS"),
     ("RepeatUntilFailure", "F", 3, "F"), ("RepeatUntilSuccess", "FFS", -1, "RRS"),
     ("RepeatUntilSuccess", "F", 3, "RRF"), ("RepeatUntilSuccess", "S", 3, "S")],
)
def test_repeat_until_statuses(name: str, script: str, max_loop: int, expected: str) -> None:
    tree = build(N(name, leaf("a", script), maxLoop=max_loop))
    assert letters([tree.tick().status for _ in expected]) == expected


def test_regression_memsequence_restarts_at_first_child_after_halt_by_priority() -> None:
    spec = N("Priority", leaf("g", "FSF"),
             N("MemSequence", leaf("a", "S"), leaf("b", "R"), leaf("c", "S"), id="m"),
             id="p")
    tree = build(spec)
    assert tree.tick().active == [ROOT, "p", "m", "b"]
    events(tree)
    snapshot = tree.tick()  # g takes over: the MemSequence is halted
    assert snapshot.status is SUCCESS
    assert snapshot.halted == ["b", "m"]
    assert events(tree) == parse_events("g:start g:tick g:end:success b:halt")
    snapshot = tree.tick()  # a new activation starts at child 0, not at b
    assert snapshot.active == [ROOT, "p", "m", "b"]
    assert events(tree) == parse_events(
        "g:start g:tick g:end:failure a:start a:tick a:end:success b:start b:tick")


def test_regression_memsequence_restarts_at_first_child_after_tree_halt() -> None:
    tree = build(N("MemSequence", leaf("a", "S"), leaf("b", "R"), id="m"))
    tree.tick()
    tree.tick()
    assert events(tree) == parse_events("a:start a:tick a:end:success b:start b:tick b:tick")
    tree.halt()
    assert events(tree) == parse_events("b:halt")
    tree.tick()
    assert events(tree) == parse_events("a:start a:tick a:end:success b:start b:tick")


def test_memsequence_does_not_retick_completed_children_while_running() -> None:
    tree = build(N("MemSequence", leaf("a", "S"), leaf("b", "RRRS"), id="m"))
    statuses = [tree.tick().status for _ in range(4)]
    assert statuses == [RUNNING, RUNNING, RUNNING, SUCCESS]
    assert events(tree).count(("tick", "a")) == 1


def test_halting_an_ancestor_first_halts_a_descendant_left_running_under_a_finished_child() -> None:
    """Found by the property test: n5 stays RUNNING under n3, which succeeded this tick; the
    Parallel's ERROR then halts n2 mid-tick. n5 must be halted before n2, not after."""
    spec = N("Parallel",
             N("Sequence",
               N("Priority", N("Scripted", script="FS", id="n4"),
                 N("Scripted", script="R", id="n5"), id="n3"),
               N("Scripted", script="R", id="n6"), id="n2"),
             N("Sequence", N("Scripted", script="RS", id="n9"),
               N("Scripted", script="E", id="n10"), id="n7"),
             successThreshold=-1, failureThreshold=-1, id="n1")
    tree = tree_from(spec)
    tree.tick()
    snapshot = tree.tick()
    assert snapshot.status is Status.ERROR
    halted = snapshot.halted
    assert halted.index("n5") < halted.index("n2") and halted.index("n6") < halted.index("n2")
    assert sorted(halted) == sorted(set(halted))  # each exactly once
    assert tree.running == []


class JumpingClock(ManualClock):
    """A manual clock that can also be set back, as a restarted simulation's /clock is."""

    def jump_to(self, seconds: float) -> None:
        self._now = seconds


@pytest.mark.parametrize(("spec", "done"), [
    (N("Wait", milliseconds=250), SUCCESS),
    (N("MaxTime", leaf("a", "R"), maxTime=250), FAILURE),
    (N("Delay", N("Succeeder"), milliseconds=250), SUCCESS),
])
def test_a_backward_clock_jump_restarts_timing_instead_of_freezing_it(
        spec: N, done: Status) -> None:
    """The clock going back 90 s (a simulation restarted) used to keep a Wait RUNNING until
    time passed its old start again; now the count restarts, as ROS 2 timers reset."""
    clock = JumpingClock(100.0)
    tree = tree_from(spec, clock=clock)
    assert tree.tick().status is RUNNING
    clock.jump_to(10.0)
    assert tree.tick().status is RUNNING
    clock.advance(0.25)
    assert tree.tick().status is done
