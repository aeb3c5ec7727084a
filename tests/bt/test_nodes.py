"""Behaviour of every stock node, table-driven, plus regressions for behavior3's defects.

Each table row is a tree spec, the clock advance before each tick, the root status expected
after each tick (one letter per tick: S, F, R, E) and the lifecycle events the `Scripted`
leaves log in each tick. Events are written compactly as ``"<uid>:<event>"`` tokens, e.g.
``"a:start a:tick a:end:success b:halt"``.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import pytest

from cyborg.bt import (
    ERROR,
    FAILURE,
    RUNNING,
    SUCCESS,
    Action,
    Composite,
    ManualClock,
    NodeRegistry,
    Status,
    TickSnapshot,
    Tree,
    TreeLoadError,
)
from tests.builders import LETTERS, N, events, registry, tree_from

# --------------------------------------------------------------------------- helpers

ROOT = "main"
"""The uid of the Subtree node that holds the tree's root (the tree id used by tree_from)."""


def leaf(uid: str, script: str) -> N:
    """A Scripted leaf with a fixed uid."""
    return N("Scripted", id=uid, script=script)


def parse_events(text: str) -> list[tuple[str, str]]:
    """``"a:start b:end:success"`` -> ``[("start", "a"), ("end:success", "b")]``."""
    parsed: list[tuple[str, str]] = []
    for token in text.split():
        uid, _, event = token.partition(":")
        parsed.append((event, uid))
    return parsed


def letters(statuses: Sequence[Status]) -> str:
    by_status = {status: letter for letter, status in LETTERS.items()}
    return "".join(by_status[status] for status in statuses)


class Advance(Action):
    """Moves the tree's clock forward while it is being ticked (the clock is in the
    blackboard under ``"clock"``), then succeeds."""

    def __init__(self, seconds: float = 1.0) -> None:
        self.seconds = seconds

    def tick(self) -> Status:
        clock: ManualClock = self.blackboard["clock"]
        clock.advance(self.seconds)
        return SUCCESS


class Returns(Action):
    """Returns a value that is not necessarily a Status, chosen by name."""

    VALUES: dict[str, object] = {
        "true": True,
        "false": False,
        "none": None,
        "one": 1,
        "text": "success",
        "status": RUNNING,
    }

    def __init__(self, value: str = "true") -> None:
        self.value = value

    def tick(self) -> Status:
        return self.VALUES[self.value]  # type: ignore[return-value]


class StartBoom(Action):
    """Raises in on_start."""

    def on_start(self) -> None:
        raise ValueError("cannot start")

    def tick(self) -> Status:
        return SUCCESS


class HaltBoom(Action):
    """Keeps running; raises in on_halt."""

    def tick(self) -> Status:
        return RUNNING

    def on_halt(self) -> None:
        raise OSError("cannot cancel")


class Forgetful(Composite):
    """A faulty composite: ticks its first child and succeeds even if the child runs on."""

    def tick(self) -> Status:
        self.children[0].execute()
        return SUCCESS


def custom_registry() -> NodeRegistry:
    reg = registry()
    for cls in (Advance, Returns, StartBoom, HaltBoom, Forgetful):
        reg.add(cls)
    return reg


def build(spec: N) -> Tree:
    tree = tree_from(spec, reg=custom_registry())
    tree.blackboard["clock"] = tree.clock
    return tree


def clock_of(tree: Tree) -> ManualClock:
    clock = tree.clock
    assert isinstance(clock, ManualClock)
    return clock


def run(tree: Tree, advances: Sequence[float]) -> list[TickSnapshot]:
    """Advance the clock by each amount (seconds) and tick once after each."""
    snapshots: list[TickSnapshot] = []
    for seconds in advances:
        clock_of(tree).advance(seconds)
        snapshots.append(tree.tick())
    return snapshots


# --------------------------------------------------------------------------- the table


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
    names = {"Sequence", "Priority", "MemSequence", "MemPriority", "Parallel", "Inverter",
             "ForceSuccess", "ForceFailure", "Repeater", "RepeatUntilFailure",
             "RepeatUntilSuccess", "Retry", "Limiter", "MaxTime", "Timeout", "Delay", "RunOnce",
             "Wait", "Failer", "Succeeder", "Runner", "Error"}
    covered = {row.spec.name for row in ROWS}
    assert names <= covered
    assert names <= set(registry().names())


# --------------------------------------------------------------------------- load errors

LOAD_ERRORS: list[tuple[N, str, str]] = [
    # (spec whose root has id "bad", the property the message must name, a message fragment)
    (N("Parallel", leaf("a", "S"), leaf("b", "S"), id="bad", successThreshold=3),
     "successThreshold", "3"),
    (N("Parallel", leaf("a", "S"), leaf("b", "S"), id="bad", successThreshold=0),
     "successThreshold", "0"),
    (N("Parallel", leaf("a", "S"), leaf("b", "S"), id="bad", successThreshold=-2),
     "successThreshold", "-2"),
    (N("Parallel", leaf("a", "S"), leaf("b", "S"), id="bad", failureThreshold=0),
     "failureThreshold", "0"),
    (N("Parallel", leaf("a", "S"), leaf("b", "S"), id="bad", failureThreshold=5),
     "failureThreshold", "5"),
    (N("Parallel", leaf("a", "S"), id="bad", failureThreshold="x"), "failureThreshold", "x"),
    (N("Repeater", leaf("a", "S"), id="bad", maxLoop=0), "maxLoop", "0"),
    (N("Repeater", leaf("a", "S"), id="bad", maxLoop=-2), "maxLoop", "-2"),
    (N("Repeater", leaf("a", "S"), id="bad", maxLoop=1.5), "maxLoop", "1.5"),
    (N("RepeatUntilFailure", leaf("a", "S"), id="bad", maxLoop=0), "maxLoop", "0"),
    (N("RepeatUntilSuccess", leaf("a", "S"), id="bad", maxLoop=-3), "maxLoop", "-3"),
    (N("Retry", leaf("a", "S"), id="bad", maxAttempts=0), "maxAttempts", "0"),
    (N("Retry", leaf("a", "S"), id="bad", maxAttempts=-7), "maxAttempts", "-7"),
    (N("Limiter", leaf("a", "S"), id="bad", maxLoop=-1), "maxLoop", "-1"),
    (N("MaxTime", leaf("a", "S"), id="bad", maxTime=0), "maxTime", "0"),
    (N("MaxTime", leaf("a", "S"), id="bad", maxTime=-10), "maxTime", "-10"),
    (N("MaxTime", leaf("a", "S"), id="bad"), "maxTime", "missing"),
    (N("Timeout", leaf("a", "S"), id="bad", milliseconds=0), "milliseconds", "0"),
    (N("Timeout", leaf("a", "S"), id="bad", milliseconds=-1), "milliseconds", "-1"),
    (N("Timeout", leaf("a", "S"), id="bad"), "milliseconds", "missing"),
    (N("Delay", leaf("a", "S"), id="bad", milliseconds=-5), "milliseconds", "-5"),
    (N("Wait", id="bad", milliseconds=-1), "milliseconds", "-1"),
    (N("Wait", id="bad", milliseconds="soon"), "milliseconds", "soon"),
]


@pytest.mark.parametrize(
    ("spec", "prop", "fragment"),
    [pytest.param(spec, prop, fragment, id=f"{spec.name}-{prop}-{fragment}")
     for spec, prop, fragment in LOAD_ERRORS],
)
def test_bad_property_is_a_load_error(spec: N, prop: str, fragment: str) -> None:
    with pytest.raises(TreeLoadError) as caught:
        build(spec)
    message = str(caught.value)
    assert "(id bad)" in message
    assert prop in message
    assert fragment in message
    errors = [problem for problem in caught.value.problems if problem.is_error]
    assert len(errors) == 1
    assert errors[0].node_id == "bad"
    assert prop in errors[0].message or errors[0].field == prop


@pytest.mark.parametrize(
    "spec",
    [pytest.param(N("Inverter", id="bad"), id="no child"),
     pytest.param(N("Failer", leaf("a", "S"), id="bad"), id="leaf with a child")],
)
def test_bad_shape_is_a_load_error(spec: N) -> None:
    with pytest.raises(TreeLoadError) as caught:
        build(spec)
    assert "(id bad)" in str(caught.value)


@pytest.mark.parametrize(
    ("spec", "status"),
    [pytest.param(N("Parallel", leaf("a", "S"), leaf("b", "S"), successThreshold=2,
                    failureThreshold=2), SUCCESS, id="Parallel thresholds = children"),
     pytest.param(N("Repeater", leaf("a", "S"), maxLoop=1), SUCCESS, id="Repeater 1"),
     pytest.param(N("Limiter", leaf("a", "S"), maxLoop=0), FAILURE, id="Limiter 0"),
     pytest.param(N("Timeout", leaf("a", "S"), milliseconds=0.5), SUCCESS, id="Timeout 0.5"),
     pytest.param(N("Repeater", leaf("a", "S"), maxLoop="2"), RUNNING, id="number as text")],
)
def test_edge_property_values_load(spec: N, status: Status) -> None:
    assert build(spec).tick().status is status


# --------------------------------------------------------------------------- lifecycle


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


# --------------------------------------------------------------------------- regressions


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
