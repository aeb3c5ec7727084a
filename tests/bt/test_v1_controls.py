"""behavior3 v1's flow-control nodes (cyborg.bt.v1_controls): composites and decorators.

Unit tests written against behavior3-ts's documented semantics (the fact sheet, section 7)
adapted to cyborg's engine (halting, ERROR): IfElse, Parallel, Race, Switch/Case and Watchdog;
Once, Repeat, the Retry nodes, AlwaysRunning, Assert, ForEach, Filter and WaitForCount; and
abandoned v1 nodes having their RUNNING descendants halted.
"""

from __future__ import annotations

import pytest

from cyborg.bt import NodeError, Status
from cyborg.bt.v1_controls import MAX_LOOPS_PER_TICK
from tests.bt.v1_samples import LogLines, calc, check, let, load, log, n, run, s, seq, wait
from tests.builders import events


# --------------------------------------------------------------------------- composites
def test_ifelse_runs_the_branch_the_condition_chose_and_resumes_it() -> None:
    tree, clock = load(n("IfElse", s("RS", "cond"), s("RS", "then"), s("S", "else")))
    assert run(tree, clock, 3) == "RRS"
    assert [tag for event, tag in events(tree) if event == "tick"] == [
        "cond", "cond", "then", "then"], "the condition is not re-tested while then runs"
    tree, clock = load(n("IfElse", s("F", "cond"), s("S", "then"), s("F", "else")))
    assert run(tree, clock, 1) == "F"
    tree, clock = load(n("IfElse", s("F", "cond"), s("S", "then")))
    assert run(tree, clock, 1) == "F", "no else branch: FAILURE, as in behavior3lua"
    tree, clock = load(n("IfElse", s("E", "cond"), s("S", "then"), s("S", "else")))
    assert run(tree, clock, 1) == "E"


def test_parallel_succeeds_once_every_child_has_finished_whatever_their_results() -> None:
    tree, clock = load(n("Parallel", s("F", "a"), s("RRS", "b"), s("RF", "c")))
    assert tree.nodes[1].name == "ParallelAll"
    assert run(tree, clock, 3) == "RRS"
    ticks = [tag for event, tag in events(tree) if event == "tick"]
    assert ticks == ["a", "b", "c", "b", "c", "b"], "finished children are not ticked again"


def test_parallel_stops_at_an_error_and_halts_the_running_children() -> None:
    tree, clock = load(n("Parallel", s("R", "a"), s("RE", "b")))
    assert run(tree, clock, 2) == "RE"
    assert ("halt", "a") in events(tree)


def test_race_returns_the_first_success_and_halts_the_others() -> None:
    tree, clock = load(n("Race", s("RRS", "slow"), s("F", "quitter"), s("RS", "quick"),
                         s("R", "never")))
    assert run(tree, clock, 2) == "RS"
    halted = [tag for event, tag in events(tree) if event == "halt"]
    assert sorted(halted) == ["never", "slow"]
    tree, clock = load(n("Race", s("RF", "a"), s("F", "b")))
    assert run(tree, clock, 2) == "RF", "FAILURE once every child has failed"


def test_switch_runs_the_first_case_whose_condition_succeeds() -> None:
    tree, clock = load(n("Switch",
                         n("Case", s("F", "c1"), s("S", "b1")),
                         n("Case", s("RS", "c2"), s("RF", "b2")),
                         n("Case", s("S", "c3"), s("S", "b3"))))
    assert run(tree, clock, 3) == "RRF", "a matched branch's FAILURE is the Switch's result"
    ticks = [tag for event, tag in events(tree) if event == "tick"]
    assert ticks == ["c1", "c2", "c2", "b2", "b2"], "earlier Cases are not tried again"
    tree, clock = load(n("Switch", n("Case", s("F", "c1"), s("S", "b1"))))
    assert run(tree, clock, 1) == "F", "no Case matches: FAILURE"


def test_a_case_outside_a_switch_is_an_error_when_ticked() -> None:
    tree, clock = load(seq(n("Case", s("S", "c"), s("S", "b"))))
    assert run(tree, clock, 1) == "E"
    assert "only as a child of a Switch" in str(tree.nodes[2].last_error)


def test_watchdog_checks_its_guard_every_tick_and_halts_the_branch_when_it_fails() -> None:
    tree, clock = load(n("Watchdog", s("SSF", "guard"), s("R", "branch"),
                         s("R", "fallback")))
    assert run(tree, clock, 3) == "RRF"
    recorded = events(tree)
    assert ("halt", "branch") in recorded and ("halt", "fallback") in recorded
    assert [tag for event, tag in recorded if event == "tick"] == [
        "guard", "branch", "guard", "branch", "guard", "fallback"]
    assert run(tree, clock, 1) == "F"  # the guard still fails (its script's last letter)


def test_watchdog_starts_an_abandoned_branch_afresh() -> None:
    """behavior3-ts forgets to clear the branch's saved place when the guard fails, so its
    next run resumes the branch midway; cyborg restarts it (the branch was halted)."""
    tree, clock = load(seq(
        let(0, "n"),
        n("Watchdog", check("n < 3"), n("Repeat", seq(calc("n + 1", "n"), wait(1))),
          log("fallback"))))
    assert run(tree, clock, 5) == "RRRFR"
    assert tree.blackboard["n"] == 1


def test_watchdog_a_running_guard_is_an_error() -> None:
    tree, clock = load(n("Watchdog", s("R", "guard"), s("R", "branch"), s("S", "fallback")))
    assert run(tree, clock, 1) == "E"
    assert "must finish in the tick it starts" in str(tree.nodes[1].last_error)
    assert ("halt", "guard") in events(tree)


# --------------------------------------------------------------------------- decorators
def test_once_succeeds_on_the_first_completion_then_fails_for_good() -> None:
    tree, clock = load(n("Once", s("RF", "child")))
    assert run(tree, clock, 4) == "RSFF"
    assert [tag for event, tag in events(tree) if event == "tick"] == ["child", "child"]


def test_once_halted_before_the_child_finished_runs_again() -> None:
    tree, clock = load(n("Race", n("Once", s("RRS", "child")), s("RS", "winner")))
    once = tree.nodes[2]
    assert run(tree, clock, 2) == "RS"
    assert ("halt", "child") in events(tree) and once.status is None
    assert run(tree, clock, 1) == "S" and once.status is Status.SUCCESS
    assert [event for event, tag in events(tree) if tag == "child"] == [
        "start", "tick", "end:success"], "the child ran again and completed"
    assert run(tree, clock, 1) == "S" and once.status is Status.FAILURE


def test_repeat_runs_a_child_that_finishes_at_once_several_times_in_one_tick() -> None:
    tree, clock = load(n("Repeat", s("S", "child"), args={"count": 3}))
    assert run(tree, clock, 1) == "S"
    assert [event for event, _ in events(tree)].count("tick") == 3
    tree, clock = load(n("Repeat", s("RSRS", "child"), args={"count": 2}))
    assert run(tree, clock, 3) == "RRS", "the second run starts in the tick the first ended"
    tree, clock = load(n("Repeat", s("SF", "child"), args={"count": 5}))
    assert run(tree, clock, 1) == "F", "a failure stops the loop"
    tree, clock = load(n("Repeat", s("S", "child"), args={"count": 0}))
    assert run(tree, clock, 1) == "S" and events(tree) == []


def test_repeat_without_count_never_spins_a_tick_forever() -> None:
    tree, clock = load(n("Repeat", s("S", "child")))
    assert run(tree, clock, 2) == "RR"
    assert [event for event, _ in events(tree)].count("tick") == 2 * MAX_LOOPS_PER_TICK


def test_repeat_count_comes_from_the_bound_input_when_there_is_one(
        caplog: pytest.LogCaptureFixture) -> None:
    tree, clock = load(n("Repeat", s("S", "child"), args={"count": 5}, i=["times"]), times=2)
    assert run(tree, clock, 1) == "S"
    assert [event for event, _ in events(tree)].count("tick") == 2
    tree, clock = load(n("Repeat", s("SF", "child"), args={"count": 5}, i=["nothing"]))
    assert run(tree, clock, 1) == "F", "an unset input falls back to 'without end'"
    assert "input 'count' reads the variable 'nothing', which is not set" in caplog.text


@pytest.mark.parametrize(("name", "script", "expected", "tries"), [
    ("RetryUntilSuccess", "F", "RRF", 2),     # one try per tick; FAILURE after the last
    ("RetryUntilSuccess", "FS", "RS", 2),
    ("RetryUntilSuccess", "RFRS", "RRS", 2),  # a long try ends; the next starts at once
    ("RetryUntilFailure", "S", "RRF", 2),
    ("RetryUntilFailure", "SF", "RS", 2),
    ("RetryUntilFailure", "E", "E", 1),
])
def test_retry_until_tries_up_to_count_times(name: str, script: str, expected: str,
                                             tries: int) -> None:
    tree, clock = load(n(name, s(script, "child"), args={"count": 2}))
    assert run(tree, clock, len(expected)) == expected
    assert [event for event, _ in events(tree)].count("start") == tries


def test_behavior3lua_repeat_until_names_map_onto_the_retry_nodes() -> None:
    tree, clock = load(seq(n("RepeatUntilFailure", s("S", "a"), args={"maxLoop": 2}),
                           n("RepeatUntilSuccess", s("F", "b"))))
    assert [node.name for node in tree][2::2] == ["RetryUntilFailure", "RetryUntilSuccess"]
    assert tree.nodes[2].properties == {"count": 2}
    assert run(tree, clock, 3) == "RRF"


def test_always_running_and_assert() -> None:
    tree, clock = load(n("AlwaysRunning", s("S", "child")))
    assert run(tree, clock, 2) == "RR"
    tree, clock = load(n("Assert", s("RSF", "child"), args={"message": "must hold"}))
    assert run(tree, clock, 3) == "RSE"
    error = tree.nodes[1].last_error
    assert isinstance(error, NodeError)
    assert str(error) == "must hold (the child returned failure)"


def test_foreach_and_filter_walk_an_array(lines: LogLines) -> None:
    tree, clock = load(seq(
        n("ForEach", seq(log("item"), wait(1)), i=["arr"], o=["item", "at"]),
        n("Filter", check("item > 1"), i=["arr"], o=["item", "big"])), arr=[1, 2, 3])
    assert run(tree, clock, 4) == "RRRS"
    assert tree.blackboard["big"] == [2, 3]
    assert "item" not in tree.blackboard and "at" not in tree.blackboard
    tree, clock = load(n("ForEach", check("item < 2"), i=["arr"], o=["item", ""]),
                       arr=[1, 2, 3])
    assert run(tree, clock, 1) == "F"
    tree, clock = load(n("Filter", check("item > 5"), i=["arr"], o=["item", "big"]),
                       arr=[1, 2])
    assert run(tree, clock, 1) == "F" and tree.blackboard["big"] == []
    tree, clock = load(n("ForEach", check("1"), i=["arr"], o=["item"]), arr=3)
    assert run(tree, clock, 1) == "E"


def test_wait_for_count_runs_for_that_many_ticks() -> None:
    tree, clock = load(n("WaitForCount", args={"tick": 3}))
    assert run(tree, clock, 4) == "RRRS"


@pytest.mark.parametrize("name", ["IfElse", "Switch", "Parallel", "Race", "Watchdog",
                                  "Repeat", "RetryUntilSuccess", "ForEach", "Once"])
def test_an_abandoned_v1_node_has_its_running_descendants_halted(name: str) -> None:
    """cyborg's (non-memory) Priority drops the v1 node when its first child starts to
    succeed; the tree then halts whatever was RUNNING below it, deepest first."""
    deep = s("R", "deep")
    inner = {
        "IfElse": lambda: n("IfElse", s("S", "c"), deep, s("S", "e")),
        "Switch": lambda: n("Switch", n("Case", s("S", "c"), deep)),
        "Watchdog": lambda: n("Watchdog", s("S", "c"), deep, s("S", "e")),
        "ForEach": lambda: n("ForEach", deep, i=["arr"], o=["item"]),
    }.get(name, lambda: n(name, deep))()
    tree, clock = load(n("Priority", s("FS", "guard"), inner), arr=[1])
    assert run(tree, clock, 2) == "RS"
    recorded = events(tree)
    assert ("halt", "deep") in recorded
    assert tree.by_uid[inner["id"]].status is None
