"""Per-node hooks: disable a subtree, force a result, breakpoints and stepping, owners, reload."""

from __future__ import annotations

import threading
import time

import pytest

from cyborg.bt import FAILURE, RUNNING, SUCCESS, HookError, HookMode, TreeRunner
from tests.builders import N, events, tree_from


def _wait_for(predicate: object, timeout: float = 5.0) -> None:
    deadline = time.monotonic() + timeout
    while not predicate():  # type: ignore[operator]
        assert time.monotonic() < deadline, "timed out"
        time.sleep(0.001)


def test_disabled_subtree_is_not_ticked_and_returns_the_chosen_status() -> None:
    tree = tree_from(N("Sequence", N("Sequence", N("Scripted", script="S", tag="inner"),
                                     id="branch"),
                       N("Scripted", script="S", tag="after")))
    tree.hooks.disable("branch", SUCCESS)
    snapshot = tree.tick()
    assert snapshot.status is SUCCESS
    assert [tag for event, tag in events(tree) if event == "tick"] == ["after"]
    assert snapshot.statuses["branch"] is SUCCESS
    tree.hooks.disable("branch", FAILURE)
    assert tree.tick().status is FAILURE
    assert events(tree) == [], "a failing disabled branch stops the Sequence"
    assert tree.hooks.clear("branch")
    assert tree.tick().status is SUCCESS
    assert ("tick", "inner") in events(tree)


def test_disabling_a_running_subtree_halts_its_actions() -> None:
    tree = tree_from(N("Sequence", N("Scripted", script="R", tag="drive"), id="top"))
    tree.tick()
    events(tree)
    tree.hooks.disable("top", FAILURE)
    assert tree.tick().status is FAILURE
    assert events(tree) == [("halt", "drive")]
    assert tree.running == []


def test_force_replaces_the_result_after_ticking() -> None:
    tree = tree_from(N("Inverter", N("Scripted", script="S", tag="check", id="check")))
    assert tree.tick().status is FAILURE
    tree.hooks.force("check", FAILURE, once=True)
    snapshot = tree.tick()
    assert snapshot.status is SUCCESS
    assert ("tick", "check") in events(tree), "a forced node still ticks"
    assert tree.hooks.get("check") is None, "a once hook goes away after use"
    assert tree.tick().status is FAILURE


def test_forcing_success_on_a_running_parent_halts_its_child() -> None:
    tree = tree_from(N("Sequence", N("Scripted", script="R", tag="slow"), id="seq"))
    tree.hooks.force("seq", SUCCESS)
    assert tree.tick().status is SUCCESS
    assert events(tree)[-1] == ("halt", "slow")


def test_bad_hooks_are_rejected_naming_the_node() -> None:
    tree = tree_from(N("Sequence", id="root"))
    with pytest.raises(HookError, match="no node with id 'nope'"):
        tree.hooks.disable("nope")
    with pytest.raises(HookError, match="node root: a disable hook returns success or failure"):
        tree.hooks.disable("root", RUNNING)
    assert tree.hooks.hooks() == []


def test_breakpoint_pauses_before_the_node_until_resumed() -> None:
    tree = tree_from(N("Sequence", N("Scripted", tag="a", id="a"), N("Scripted", tag="b", id="b")))
    tree.hooks.breakpoint("b")
    done = threading.Event()

    def tick_once() -> None:
        tree.tick()
        done.set()

    thread = threading.Thread(target=tick_once)
    thread.start()
    _wait_for(lambda: tree.hooks.paused_at == "b")
    assert [tag for event, tag in tree.blackboard["events"] if event == "tick"] == ["a"]
    assert not done.is_set()
    assert tree.hooks.resume()
    assert done.wait(5)
    thread.join()
    assert tree.hooks.paused_at is None
    assert ("tick", "b") in events(tree)
    assert tree.hooks.get("b") is not None, "a breakpoint stays until cleared"


def test_step_stops_at_the_next_node_to_tick() -> None:
    tree = tree_from(N("Sequence", N("Scripted", tag="a", id="a"), N("Scripted", tag="b", id="b"),
                       N("Scripted", tag="c", id="c")))
    tree.hooks.breakpoint("a", once=True)
    thread = threading.Thread(target=tree.tick)
    thread.start()
    _wait_for(lambda: tree.hooks.paused_at == "a")
    assert tree.hooks.step()
    _wait_for(lambda: tree.hooks.paused_at == "b")
    assert tree.hooks.step()
    _wait_for(lambda: tree.hooks.paused_at == "c")
    assert tree.hooks.resume()
    thread.join(5)
    assert not thread.is_alive()
    assert [tag for event, tag in events(tree) if event == "tick"] == ["a", "b", "c"]
    assert tree.hooks.hooks() == [] and all(node.hook is None for node in tree)
    assert not tree.hooks.step(), "nothing to step when no tick waits"


def test_owner_hooks_are_released_together() -> None:
    tree = tree_from(N("Sequence", N("Succeeder", id="x"), N("Succeeder", id="y"),
                       N("Succeeder", id="z")))
    tree.hooks.disable("x", owner="monitor")
    tree.hooks.breakpoint("y", owner="monitor")
    tree.hooks.force("z", FAILURE, owner="other")
    assert [hook.mode for hook in tree.hooks.hooks()] == [
        HookMode.DISABLE, HookMode.BREAKPOINT, HookMode.FORCE]
    assert tree.hooks.clear_owner("monitor") == ["x", "y"]
    assert [hook.node for hook in tree.hooks.hooks()] == ["z"]


def test_pausing_the_runner_releases_a_waiting_breakpoint() -> None:
    tree = tree_from(N("Sequence", N("Scripted", script="R", tag="job", id="job")))
    tree.hooks.breakpoint("job")
    runner = TreeRunner(tree)
    runner.start()
    _wait_for(lambda: tree.hooks.paused_at == "job")
    runner.pause(halt=True)  # must not deadlock on the waiting tick
    runner.stop()
    runner.join(5)
    assert runner.stopped


def test_replace_tree_halts_the_old_one_and_carries_hooks_over() -> None:
    old = tree_from(N("Sequence", N("Scripted", script="R", tag="old"), id="root"))
    new = tree_from(N("Sequence", N("Scripted", script="S", tag="new"), id="root"))
    old.hooks.disable("root", SUCCESS)
    old.hooks.clear("root")
    old.tick()
    old.hooks.force("root", FAILURE)
    runner = TreeRunner(old)
    assert runner.replace_tree(new) is old
    assert events(old)[-1] == ("halt", "old")
    assert runner.tree is new and new.hooks.get("root") is not None
    assert runner.step().status is FAILURE


def test_timing_measures_every_visit_and_leaves_breakpoint_waits_out() -> None:
    tree = tree_from(N("Sequence", N("Scripted", script="S", tag="a", id="a"),
                       N("Scripted", script="S", tag="b", id="b"), id="top"))
    assert not tree.tick().timed, "untimed by default: nodes run unwrapped"
    assert "execute" not in vars(tree.by_uid["a"])
    tree.hooks.timing = True
    snapshot = tree.tick()
    durations = dict(zip((uid for uid, _ in snapshot.visited), snapshot.visit_durations,
                         strict=True))
    assert {"a", "b", "top"} <= set(durations)
    assert all(value >= 0 for value in durations.values())
    assert durations["top"] >= durations["a"] + durations["b"], "a parent includes its subtree"
    tree.hooks.breakpoint("b", once=True)
    ticking = threading.Thread(target=tree.tick)
    ticking.start()
    _wait_for(lambda: tree.hooks.paused_at == "b")
    time.sleep(0.2)
    tree.hooks.resume()
    ticking.join(5)
    assert tree.last is not None
    top = dict(zip((uid for uid, _ in tree.last.visited), tree.last.visit_durations,
                   strict=True))["top"]
    assert top < 0.1, f"the 0.2 s wait at the breakpoint is not the tree's time ({top:.3f} s)"
    tree.hooks.timing = False
    assert not tree.tick().timed
    assert "execute" not in vars(tree.by_uid["a"]), "untimed nodes are unwrapped again"
