"""The stock nodes' lifecycle: ticks, halts, exceptions and time, as the snapshots report them.

What a tick snapshot reports (visits, the active path, halts); halting deepest first, once,
and never a node that completed; a node that raises (in tick, on_start or on_halt) or returns
what is not a Status is an ERROR logged once while the tree keeps ticking; a node left running
under a completed parent is halted; time is read once at the start of each tick.
"""

from __future__ import annotations

import logging

import pytest

from cyborg.bt import ERROR, FAILURE, RUNNING, SUCCESS, Status
from tests.bt.node_helpers import ROOT, build, clock_of, leaf, parse_events
from tests.builders import N, events


def test_snapshot_reports_visits_active_path_and_halts() -> None:
    tree = build(N("Sequence", N("Inverter", leaf("a", "R"), id="i"), leaf("b", "S"), id="s"))
    snapshot = tree.tick()
    assert snapshot.status is RUNNING
    assert snapshot.visited == [("a", RUNNING), ("i", RUNNING), ("s", RUNNING),
                                (ROOT, RUNNING)]
    assert snapshot.active == [ROOT, "s", "i", "a"]
    assert snapshot.halted == []
    assert [node.uid for node in tree.running] == ["a", "i", "s", ROOT]

    halted = tree.halt()
    assert [node.uid for node in halted] == ["a", "i", "s", ROOT]  # deepest first
    assert events(tree) == parse_events("a:start a:tick a:halt")
    assert all(node.status is None for node in halted)
    assert tree.running == []
    assert tree.halt() == []  # nothing left to halt: on_halt ran exactly once
    assert events(tree) == []

    snapshot = tree.tick()  # a new activation after the halt
    assert snapshot.halted == []
    assert events(tree) == parse_events("a:start a:tick")


def test_halt_on_idle_tree_does_nothing() -> None:
    tree = build(N("Sequence", leaf("a", "S")))
    assert tree.halt() == []
    tree.tick()
    events(tree)
    assert tree.halt() == []
    assert events(tree) == []


def test_completed_node_is_not_halted() -> None:
    tree = build(N("Priority", leaf("a", "FS"), leaf("b", "RF"), id="p"))
    tree.tick()
    events(tree)
    snapshot = tree.tick()  # a succeeds: b (RUNNING) is halted once, a is not
    assert snapshot.halted == ["b"]
    assert events(tree) == parse_events("a:start a:tick a:end:success b:halt")
    snapshot = tree.tick()
    assert snapshot.halted == []
    assert events(tree) == parse_events("a:start a:tick a:end:success")


def test_halting_goes_deepest_first_when_a_branch_is_abandoned() -> None:
    spec = N("Priority",
             N("Sequence", leaf("a", "FS"), id="s1"),
             N("Sequence", N("Inverter", leaf("b", "R"), id="i"), id="s2"),
             id="p")
    tree = build(spec)
    assert tree.tick().active == [ROOT, "p", "s2", "i", "b"]
    snapshot = tree.tick()
    assert snapshot.status is SUCCESS
    assert snapshot.halted == ["b", "i", "s2"]
    assert snapshot.active == []


def test_node_exception_returns_error_logged_once_and_tree_keeps_ticking(
        caplog: pytest.LogCaptureFixture) -> None:
    tree = build(N("Sequence", leaf("x", "XXXS"), leaf("b", "S"), id="s"))
    with caplog.at_level(logging.DEBUG, logger="cyborg.bt"):
        statuses = [tree.tick().status for _ in range(4)]
    assert statuses == [ERROR, ERROR, ERROR, SUCCESS]
    log = events(tree)
    assert log[:3] == parse_events("x:start x:tick x:end:error")
    assert log[-6:] == parse_events(
        "x:start x:tick x:end:success b:start b:tick b:end:success")
    errors = [record for record in caplog.records
              if record.name == "cyborg.bt" and record.levelno >= logging.ERROR]
    assert len(errors) == 1
    record = errors[0]
    assert record.exc_info is not None
    assert isinstance(record.exc_info[1], RuntimeError)
    assert "x" in record.getMessage().split()
    assert "scripted failure in x" in caplog.text  # the traceback is in the log
    node = tree.by_uid["x"]
    assert isinstance(node.last_error, RuntimeError)
    assert node.error_count == 3


def test_exception_in_on_start_returns_error(caplog: pytest.LogCaptureFixture) -> None:
    tree = build(N("Priority", N("StartBoom", id="boom"), leaf("b", "S")))
    with caplog.at_level(logging.ERROR, logger="cyborg.bt"):
        snapshot = tree.tick()
    assert snapshot.statuses["boom"] is ERROR
    assert snapshot.status is ERROR
    assert len(caplog.records) == 1
    assert "boom" in caplog.records[0].getMessage()
    assert caplog.records[0].exc_info is not None


@pytest.mark.parametrize(
    ("value", "status"),
    [("true", SUCCESS), ("false", FAILURE), ("status", RUNNING), ("none", ERROR),
     ("one", ERROR), ("text", ERROR)],
)
def test_tick_return_value_coercion(value: str, status: Status,
                                    caplog: pytest.LogCaptureFixture) -> None:
    tree = build(N("Returns", id="r", value=value))
    with caplog.at_level(logging.ERROR, logger="cyborg.bt"):
        snapshot = tree.tick()
    assert snapshot.statuses["r"] is status
    assert snapshot.status is status
    if status is ERROR:
        assert len(caplog.records) == 1
        assert "r" in caplog.records[0].getMessage().split()
        assert isinstance(tree.by_uid["r"].last_error, TypeError)
    else:
        assert caplog.records == []


def test_exception_in_on_halt_is_logged_and_halting_goes_on(
        caplog: pytest.LogCaptureFixture) -> None:
    tree = build(N("Sequence", N("HaltBoom", id="h"), id="s"))
    tree.tick()
    with caplog.at_level(logging.ERROR, logger="cyborg.bt"):
        halted = tree.halt()
    assert [node.uid for node in halted] == ["h", "s", ROOT]
    assert len(caplog.records) == 1
    assert "h" in caplog.records[0].getMessage().split()
    assert "on_halt" in caplog.records[0].getMessage()
    assert tree.running == []


def test_node_left_running_under_a_completed_parent_is_halted() -> None:
    tree = build(N("Forgetful", leaf("a", "R"), id="f"))
    snapshot = tree.tick()
    assert snapshot.status is SUCCESS
    assert snapshot.halted == ["a"]
    assert snapshot.active == []
    assert events(tree) == parse_events("a:start a:tick a:halt")
    tree.tick()
    assert events(tree) == parse_events("a:start a:tick a:halt")


def test_time_is_read_once_at_the_start_of_each_tick() -> None:
    tree = build(N("Sequence", N("Advance", seconds=1.0), N("Wait", id="w", milliseconds=1500)))
    snapshots = [tree.tick() for _ in range(3)]
    # Advance moves the clock 1 s during every tick, but the Wait sees the tick's start time:
    # started at 0, it has seen 1000 ms in the second tick and 2000 ms in the third.
    assert [snapshot.time for snapshot in snapshots] == [0.0, 1.0, 2.0]
    assert [snapshot.statuses["w"] for snapshot in snapshots] == [RUNNING, RUNNING, SUCCESS]
    assert clock_of(tree).now() == 3.0
