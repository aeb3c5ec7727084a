"""Behaviour of every stock node (leaves, composites and decorators), table-driven.


Each table row is a tree spec, the clock advance before each tick, the root status expected
after each tick (one letter per tick: S, F, R, E) and the lifecycle events the `Scripted`
leaves log in each tick. Events are written compactly as ``"<uid>:<event>"`` tokens, e.g.
``"a:start a:tick a:end:success b:halt"``.
"""

from __future__ import annotations

from dataclasses import dataclass

import pytest

from cyborg.bt import Status
from tests.bt.node_helpers import ROOT, build, clock_of, leaf, letters, parse_events
from tests.builders import N, events, registry


@dataclass(frozen=True)
class Row:
    """One scenario: tick ``spec`` once per entry of ``statuses``."""

    name: str
    spec: N
    statuses: str
    """Expected root status per tick, one letter each (S, F, R, E)."""
    events: tuple[str, ...] = ()
    """Expected Scripted events per tick (see :func:`parse_events`); () means none at all."""
    advances: tuple[float, ...] = ()
    """Clock advance in seconds before each tick; () means no advance."""
    halted: tuple[str, ...] = ()
    """Expected snapshot.halted per tick as space-separated uids; () means not checked."""


ROWS: list[Row] = [
    # ----------------------------------------------------------------- stock leaves
    Row("Succeeder", N("Succeeder"), "SS"),
    Row("Failer", N("Failer"), "FF"),
    Row("Runner", N("Runner"), "RRR"),
    Row("Error", N("Error"), "EE"),
    Row("Wait runs until its time has passed, then restarts",
        N("Wait", milliseconds=250), "RRSR", advances=(0, 0.125, 0.125, 0)),
    Row("Wait succeeds exactly at its time", N("Wait", milliseconds=500), "RS",
        advances=(0, 0.5)),
    Row("Wait 0 succeeds at once", N("Wait", milliseconds=0), "SS"),
    Row("Wait defaults to 0", N("Wait"), "S"),
    # ----------------------------------------------------------------- Sequence
    Row("Sequence all succeed", N("Sequence", leaf("a", "S"), leaf("b", "S")), "S",
        ("a:start a:tick a:end:success b:start b:tick b:end:success",)),
    Row("Sequence stops at a failure", N("Sequence", leaf("a", "F"), leaf("b", "S")), "F",
        ("a:start a:tick a:end:failure",)),
    Row("Sequence stops at an error", N("Sequence", leaf("a", "E"), leaf("b", "S")), "E",
        ("a:start a:tick a:end:error",)),
    Row("Sequence without memory re-ticks earlier children",
        N("Sequence", leaf("a", "S"), leaf("b", "RS")), "RS",
        ("a:start a:tick a:end:success b:start b:tick",
         "a:start a:tick a:end:success b:tick b:end:success")),
    Row("Sequence halts the running child when an earlier one fails",
        N("Sequence", leaf("a", "SF"), leaf("b", "R"), id="s"), "RF",
        ("a:start a:tick a:end:success b:start b:tick",
         "a:start a:tick a:end:failure b:halt"),
        halted=("", "b")),
    Row("Sequence without children succeeds", N("Sequence"), "S"),
    # ----------------------------------------------------------------- Priority
    Row("Priority stops at the first success",
        N("Priority", leaf("a", "S"), leaf("b", "S")), "S",
        ("a:start a:tick a:end:success",)),
    Row("Priority fails when all fail", N("Priority", leaf("a", "F"), leaf("b", "F")), "F",
        ("a:start a:tick a:end:failure b:start b:tick b:end:failure",)),
    Row("Priority stops at an error", N("Priority", leaf("a", "E"), leaf("b", "S")), "E",
        ("a:start a:tick a:end:error",)),
    Row("Priority without memory re-ticks earlier children",
        N("Priority", leaf("a", "F"), leaf("b", "RS")), "RS",
        ("a:start a:tick a:end:failure b:start b:tick",
         "a:start a:tick a:end:failure b:tick b:end:success")),
    Row("Priority: a higher child taking over halts the running one",
        N("Priority", leaf("a", "FS"), leaf("b", "R"), id="p"), "RS",
        ("a:start a:tick a:end:failure b:start b:tick",
         "a:start a:tick a:end:success b:halt"),
        halted=("", "b")),
    Row("Priority without children fails", N("Priority"), "F"),
    # ----------------------------------------------------------------- MemSequence
    Row("MemSequence resumes at the running child and restarts when done",
        N("MemSequence", leaf("a", "S"), leaf("b", "RS"), leaf("c", "S")), "RSS",
        ("a:start a:tick a:end:success b:start b:tick",
         "b:tick b:end:success c:start c:tick c:end:success",
         "a:start a:tick a:end:success b:start b:tick b:end:success "
         "c:start c:tick c:end:success")),
    Row("MemSequence fails when the resumed child fails",
        N("MemSequence", leaf("a", "S"), leaf("b", "RF"), leaf("c", "S")), "RF",
        ("a:start a:tick a:end:success b:start b:tick", "b:tick b:end:failure")),
    Row("MemSequence halted by a higher branch starts again at its first child",
        N("Priority", leaf("g", "FSF"),
          N("MemSequence", leaf("a", "S"), leaf("b", "R"), id="m")), "RSR",
        ("g:start g:tick g:end:failure a:start a:tick a:end:success b:start b:tick",
         "g:start g:tick g:end:success b:halt",
         "g:start g:tick g:end:failure a:start a:tick a:end:success b:start b:tick"),
        halted=("", "b m", "")),
    # ----------------------------------------------------------------- ResumingSequence
    Row("ResumingSequence halted by a higher branch resumes at the child it was running",
        N("Priority", leaf("g", "FSF"),
          N("ResumingSequence", leaf("a", "S"), leaf("b", "RRS"), leaf("c", "S"), id="m")),
        "RSRS",
        ("g:start g:tick g:end:failure a:start a:tick a:end:success b:start b:tick",
         "g:start g:tick g:end:success b:halt",
         "g:start g:tick g:end:failure b:start b:tick",
         "g:start g:tick g:end:failure b:tick b:end:success c:start c:tick c:end:success"),
        halted=("", "b m", "", "")),
    Row("ResumingSequence starts at its first child again once it completes",
        N("ResumingSequence", leaf("a", "S"), leaf("b", "RSR")), "RSR",
        ("a:start a:tick a:end:success b:start b:tick",
         "b:tick b:end:success",
         "a:start a:tick a:end:success b:start b:tick")),
    Row("ResumingSequence that fails starts at its first child again",
        N("ResumingSequence", leaf("a", "S"), leaf("b", "RFR")), "RFR",
        ("a:start a:tick a:end:success b:start b:tick",
         "b:tick b:end:failure",
         "a:start a:tick a:end:success b:start b:tick")),
    # ----------------------------------------------------------------- MemPriority
    Row("MemPriority resumes at the running child and restarts when done",
        N("MemPriority", leaf("a", "F"), leaf("b", "RF"), leaf("c", "S")), "RSS",
        ("a:start a:tick a:end:failure b:start b:tick",
         "b:tick b:end:failure c:start c:tick c:end:success",
         "a:start a:tick a:end:failure b:start b:tick b:end:failure "
         "c:start c:tick c:end:success")),
    Row("MemPriority succeeds when the resumed child succeeds",
        N("MemPriority", leaf("a", "F"), leaf("b", "RS"), leaf("c", "S")), "RS",
        ("a:start a:tick a:end:failure b:start b:tick", "b:tick b:end:success")),
    # ----------------------------------------------------------------- Parallel
    Row("Parallel succeeds when all succeed; completed children are not re-ticked",
        N("Parallel", leaf("a", "RS"), leaf("b", "RRS")), "RRS",
        ("a:start a:tick b:start b:tick", "a:tick a:end:success b:tick",
         "b:tick b:end:success")),
    Row("Parallel starts every child again in a new activation",
        N("Parallel", leaf("a", "S"), leaf("b", "S")), "SS",
        ("a:start a:tick a:end:success b:start b:tick b:end:success",
         "a:start a:tick a:end:success b:start b:tick b:end:success")),
    Row("Parallel fails at the first failure and halts running children",
        N("Parallel", leaf("a", "RF"), leaf("b", "R"), id="p"), "RF",
        ("a:start a:tick b:start b:tick", "a:tick a:end:failure b:tick b:halt"),
        halted=("", "b")),
    Row("Parallel fails when all complete below the success threshold",
        N("Parallel", leaf("a", "S"), leaf("b", "RF"), successThreshold=-1,
          failureThreshold=-1), "RF",
        ("a:start a:tick a:end:success b:start b:tick", "b:tick b:end:failure")),
    Row("Parallel successThreshold 1 succeeds with one child and halts the rest",
        N("Parallel", leaf("a", "RS"), leaf("b", "R"), successThreshold=1), "RS",
        ("a:start a:tick b:start b:tick", "a:tick a:end:success b:tick b:halt"),
        halted=("", "b")),
    Row("Parallel failureThreshold 2 needs two failures",
        N("Parallel", leaf("a", "F"), leaf("b", "RF"), leaf("c", "R"), failureThreshold=2),
        "RF",
        ("a:start a:tick a:end:failure b:start b:tick c:start c:tick",
         "b:tick b:end:failure c:tick c:halt"),
        halted=("", "c")),
    Row("Parallel halts its running children as soon as it is decided",
        N("Priority", N("Parallel", leaf("a", "RF"), leaf("b", "R"), id="p"), leaf("c", "S")),
        "RS",
        ("a:start a:tick b:start b:tick",
         "a:tick a:end:failure b:tick b:halt c:start c:tick c:end:success"),
        halted=("", "b")),
    Row("Parallel returns a child's ERROR and halts the others",
        N("Parallel", leaf("a", "R"), leaf("b", "E"), leaf("c", "R")), "E",
        ("a:start a:tick b:start b:tick b:end:error a:halt",), halted=("a",)),
    # ----------------------------------------------------------------- Inverter
    Row("Inverter turns SUCCESS into FAILURE", N("Inverter", leaf("a", "S")), "F",
        ("a:start a:tick a:end:success",)),
    Row("Inverter turns FAILURE into SUCCESS", N("Inverter", leaf("a", "F")), "S",
        ("a:start a:tick a:end:failure",)),
    Row("Inverter passes RUNNING and ERROR", N("Inverter", leaf("a", "RE")), "RE",
        ("a:start a:tick", "a:tick a:end:error")),
    # ----------------------------------------------------------------- ForceSuccess
    Row("ForceSuccess turns FAILURE into SUCCESS", N("ForceSuccess", leaf("a", "F")), "S",
        ("a:start a:tick a:end:failure",)),
    Row("ForceSuccess keeps SUCCESS", N("ForceSuccess", leaf("a", "S")), "S",
        ("a:start a:tick a:end:success",)),
    Row("ForceSuccess passes RUNNING and ERROR", N("ForceSuccess", leaf("a", "RE")), "RE",
        ("a:start a:tick", "a:tick a:end:error")),
    # ----------------------------------------------------------------- ForceFailure
    Row("ForceFailure turns SUCCESS into FAILURE", N("ForceFailure", leaf("a", "S")), "F",
        ("a:start a:tick a:end:success",)),
    Row("ForceFailure keeps FAILURE", N("ForceFailure", leaf("a", "F")), "F",
        ("a:start a:tick a:end:failure",)),
    Row("ForceFailure passes RUNNING and ERROR", N("ForceFailure", leaf("a", "RE")), "RE",
        ("a:start a:tick", "a:tick a:end:error")),
    # ----------------------------------------------------------------- Repeater
    Row("Repeater loops once per tick and returns the last status after maxLoop",
        N("Repeater", leaf("a", "S"), maxLoop=3), "RRSR",
        ("a:start a:tick a:end:success",) * 4),
    Row("Repeater returns the child's last status", N("Repeater", leaf("a", "SF"), maxLoop=2),
        "RF", ("a:start a:tick a:end:success", "a:start a:tick a:end:failure")),
    Row("Repeater maxLoop 1 returns the child's status at once",
        N("Repeater", leaf("a", "F"), maxLoop=1), "FF",
        ("a:start a:tick a:end:failure",) * 2),
    Row("Repeater -1 repeats forever", N("Repeater", leaf("a", "S"), maxLoop=-1), "RRRRR",
        ("a:start a:tick a:end:success",) * 5),
    Row("Repeater defaults to forever", N("Repeater", leaf("a", "F")), "RRR",
        ("a:start a:tick a:end:failure",) * 3),
    Row("Repeater waits for a running child; only completions count",
        N("Repeater", leaf("a", "RSRS"), maxLoop=2), "RRRS",
        ("a:start a:tick", "a:tick a:end:success", "a:start a:tick",
         "a:tick a:end:success")),
    Row("Repeater stops at an ERROR", N("Repeater", leaf("a", "SE"), maxLoop=5), "RE",
        ("a:start a:tick a:end:success", "a:start a:tick a:end:error")),
    # ----------------------------------------------------------------- RepeatUntilFailure
    Row("RepeatUntilFailure stops with FAILURE when the child fails",
        N("RepeatUntilFailure", leaf("a", "SSF")), "RRF",
        ("a:start a:tick a:end:success", "a:start a:tick a:end:success",
         "a:start a:tick a:end:failure")),
    Row("RepeatUntilFailure succeeds after maxLoop successes",
        N("RepeatUntilFailure", leaf("a", "S"), maxLoop=2), "RS",
        ("a:start a:tick a:end:success",) * 2),
    Row("RepeatUntilFailure passes RUNNING", N("RepeatUntilFailure", leaf("a", "RF"), maxLoop=3),
        "RF", ("a:start a:tick", "a:tick a:end:failure")),
    # ----------------------------------------------------------------- RepeatUntilSuccess
    Row("RepeatUntilSuccess stops with SUCCESS when the child succeeds",
        N("RepeatUntilSuccess", leaf("a", "FFS")), "RRS",
        ("a:start a:tick a:end:failure", "a:start a:tick a:end:failure",
         "a:start a:tick a:end:success")),
    Row("RepeatUntilSuccess fails after maxLoop failures",
        N("RepeatUntilSuccess", leaf("a", "F"), maxLoop=2), "RF",
        ("a:start a:tick a:end:failure",) * 2),
    # ----------------------------------------------------------------- Retry
    Row("Retry fails after maxAttempts failures", N("Retry", leaf("a", "F"), maxAttempts=3),
        "RRF", ("a:start a:tick a:end:failure",) * 3),
    Row("Retry succeeds when an attempt succeeds", N("Retry", leaf("a", "FS")), "RS",
        ("a:start a:tick a:end:failure", "a:start a:tick a:end:success")),
    Row("Retry defaults to 3 attempts", N("Retry", leaf("a", "F")), "RRF",
        ("a:start a:tick a:end:failure",) * 3),
    Row("Retry -1 retries forever", N("Retry", leaf("a", "F"), maxAttempts=-1), "RRRRR",
        ("a:start a:tick a:end:failure",) * 5),
    # ----------------------------------------------------------------- Limiter
    Row("Limiter allows maxLoop completions, then fails without ticking",
        N("Limiter", leaf("a", "S"), maxLoop=2), "SSFF",
        ("a:start a:tick a:end:success", "a:start a:tick a:end:success", "", "")),
    Row("Limiter counts completions, not ticks",
        N("Limiter", leaf("a", "RS"), maxLoop=1), "RSF",
        ("a:start a:tick", "a:tick a:end:success", "")),
    Row("Limiter counts failures as completions",
        N("Limiter", leaf("a", "F"), maxLoop=1), "FF",
        ("a:start a:tick a:end:failure", "")),
    Row("Limiter 0 never ticks the child", N("Limiter", leaf("a", "S"), maxLoop=0), "FF",
        ("", "")),
    # ----------------------------------------------------------------- MaxTime / Timeout
    Row("MaxTime halts the child at the deadline and fails without ticking it",
        N("MaxTime", leaf("a", "R"), maxTime=500), "RRF",
        ("a:start a:tick", "a:tick", "a:halt"), advances=(0, 0.25, 0.25),
        halted=("", "", "a")),
    Row("Timeout halts the child at the deadline and fails without ticking it",
        N("Timeout", leaf("a", "R"), milliseconds=500), "RRF",
        ("a:start a:tick", "a:tick", "a:halt"), advances=(0, 0.25, 0.25),
        halted=("", "", "a")),
    Row("Timeout halts the child before its parent goes on",
        N("Priority", N("Timeout", leaf("a", "R"), id="t", milliseconds=250), leaf("c", "S")),
        "RS", ("a:start a:tick", "a:halt c:start c:tick c:end:success"), advances=(0, 0.25),
        halted=("", "a")),
    Row("Timeout returns the child's result before the deadline",
        N("Timeout", leaf("a", "RS"), milliseconds=500), "RS",
        ("a:start a:tick", "a:tick a:end:success"), advances=(0, 0.25)),
    Row("Timeout passes a child's FAILURE",
        N("Timeout", leaf("a", "F"), milliseconds=500), "F",
        ("a:start a:tick a:end:failure",)),
    Row("Timeout restarts its deadline in each activation",
        N("Timeout", leaf("a", "RSRR"), milliseconds=250), "RSRRF",
        ("a:start a:tick", "a:tick a:end:success", "a:start a:tick", "a:tick", "a:halt"),
        advances=(0, 0.125, 0.125, 0.125, 0.125)),
    Row("Timeout fails after a long gap even if the child would finish",
        N("Timeout", leaf("a", "RS"), milliseconds=250), "RF",
        ("a:start a:tick", "a:halt"), advances=(0, 2.0)),
    # ----------------------------------------------------------------- Delay
    Row("Delay runs until its time has passed, then ticks the child",
        N("Delay", leaf("a", "S"), milliseconds=500), "RRSR",
        ("", "", "a:start a:tick a:end:success", ""), advances=(0, 0.25, 0.25, 0)),
    Row("Delay keeps ticking a running child once its time has passed",
        N("Delay", leaf("a", "RF"), milliseconds=250), "RRF",
        ("", "a:start a:tick", "a:tick a:end:failure"), advances=(0, 0.25, 0)),
    Row("Delay 0 ticks the child at once", N("Delay", leaf("a", "S"), milliseconds=0), "S",
        ("a:start a:tick a:end:success",)),
    # ----------------------------------------------------------------- RunOnce
    Row("RunOnce ticks the child until it completes, then repeats its result",
        N("RunOnce", leaf("a", "RFS")), "RFFF",
        ("a:start a:tick", "a:tick a:end:failure", "", "")),
    Row("RunOnce remembers SUCCESS", N("RunOnce", leaf("a", "SF")), "SSS",
        ("a:start a:tick a:end:success", "", "")),
]


@pytest.mark.parametrize("row", [pytest.param(row, id=row.name) for row in ROWS])
def test_stock_node(row: Row) -> None:
    ticks = len(row.statuses)
    advances = row.advances or (0.0,) * ticks
    expected_events = row.events or ("",) * ticks
    assert len(advances) == ticks and len(expected_events) == ticks, "malformed row"
    tree = build(row.spec)

    statuses: list[Status] = []
    for number, seconds in enumerate(advances, start=1):
        clock_of(tree).advance(seconds)
        snapshot = tree.tick()
        statuses.append(snapshot.status)
        assert events(tree) == parse_events(expected_events[number - 1]), f"tick {number}"
        if row.halted:
            assert snapshot.halted == row.halted[number - 1].split(), f"tick {number}"
        assert snapshot.visited[-1] == (ROOT, snapshot.status)
    assert letters(statuses) == row.statuses


def test_every_stock_node_is_in_the_table() -> None:
    names = {"Sequence", "Priority", "MemSequence", "MemPriority", "ResumingSequence",
             "Parallel", "Inverter",
             "ForceSuccess", "ForceFailure", "Repeater", "RepeatUntilFailure",
             "RepeatUntilSuccess", "Retry", "Limiter", "MaxTime", "Timeout", "Delay", "RunOnce",
             "Wait", "Failer", "Succeeder", "Runner", "Error"}
    covered = {row.spec.name for row in ROWS}
    assert names <= covered
    assert names <= set(registry().names())
