"""Per-node hooks: disable a subtree, force a result, breakpoints and stepping, owners, reload."""

from __future__ import annotations

import threading
import time
from math import isnan

import pytest

from cyborg.bt import (
    FAILURE,
    RUNNING,
    SUCCESS,
    Action,
    Blackboard,
    HookError,
    HookMode,
    ManualClock,
    Node,
    Sequence,
    Status,
    TickLoop,
    Tree,
)
from cyborg.bt.node import TickRecord
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
    assert tree.hooks.hooks() == []
    assert all(node.pre_tick is None and node.post_tick is None for node in tree), \
        "once stepping ends and the hooks are gone, every node's slots are empty again"
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
    runner = TickLoop(tree)
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
    runner = TickLoop(old)
    assert runner.replace_tree(new) is old
    assert events(old)[-1] == ("halt", "old")
    assert runner.tree is new and new.hooks.get("root") is not None
    assert runner.step().status is FAILURE


def test_timing_measures_every_visit_and_leaves_breakpoint_waits_out() -> None:
    tree = tree_from(N("Sequence", N("Scripted", script="S", tag="a", id="a"),
                       N("Scripted", script="S", tag="b", id="b"), id="top"))
    assert not tree.timing and not tree.tick().timed, "untimed by default"
    assert "execute" not in vars(tree.by_uid["a"])
    tree.timing = True
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
    tree.timing = False
    assert not tree.tick().timed
    assert "execute" not in vars(tree.by_uid["a"]), "timing never replaces execute"
    assert not any(node.timed for node in tree), "untimed nodes take the fast path again"


def test_timing_is_a_tree_option_applied_between_ticks() -> None:
    seen: list[bool] = []

    class Flip(Action):
        """Switches the tree's timing over from inside a tick, and notes if it is timed."""

        def tick(self) -> Status:
            tree: Tree = self.blackboard["tree"]
            tree.timing = not tree.timing
            seen.append(self.timed)
            return SUCCESS

    tree = _hand_tree(Counter(), Flip(), timing=True)
    tree.blackboard["tree"] = tree
    assert tree.timing and all(node.timed for node in tree), "Tree(..., timing=True)"
    snapshot = tree.tick()
    assert not tree.timing, "the setting changes at once"
    assert snapshot.timed and not any(isnan(value) for value in snapshot.visit_durations), \
        "but the tick that changed it was timed completely"
    assert seen == [True] and all(node.timed for node in tree), "nothing changed mid-tick"
    snapshot = tree.tick()
    assert not snapshot.timed and seen == [True, False], "the next tick was not timed at all"
    assert tree.timing and not any(node.timed for node in tree)
    assert tree.tick().timed
    assert tree.hooks.timing is tree.timing is False, "hooks.timing is another name for it"
    tree.hooks.timing = True
    assert tree.timing


def test_hooks_use_the_node_slots_and_never_replace_execute() -> None:
    tree = tree_from(N("Sequence", N("Scripted", script="S", tag="a", id="a"),
                       N("Scripted", script="S", tag="b", id="b"), id="top"))
    node_a, node_b = tree.by_uid["a"], tree.by_uid["b"]
    tree.hooks.disable("a", SUCCESS)
    tree.hooks.force("b", FAILURE)
    tree.hooks.breakpoint("top")
    tree.hooks.clear("top")
    for node in tree:
        assert "execute" not in vars(node), "the class's own execute runs, through the slots"
    assert node_a.pre_tick == tree.hooks.before_tick
    assert node_b.post_tick == tree.hooks.after_tick
    assert tree.by_uid["top"].pre_tick is None, "an unhooked node keeps empty slots"
    snapshot = tree.tick()
    assert snapshot.status is FAILURE
    assert [tag for event, tag in events(tree) if event == "tick"] == ["b"]
    tree.hooks.clear_all()
    assert all(node.pre_tick is None and node.post_tick is None for node in tree)
    assert not any("execute" in vars(node) for node in tree)
    assert tree.tick().status is SUCCESS


class Counter(Action):
    """A user's own node: counts its ticks and returns SUCCESS."""

    def __init__(self) -> None:
        self.ticks = 0

    def tick(self) -> Status:
        self.ticks += 1
        return SUCCESS


def _hand_tree(*leaves: Node, timing: bool = False) -> Tree:
    """A tree built by hand, without a file: a Sequence ``top`` over ``leaves`` (ids l0, l1…)."""
    record, blackboard = TickRecord(), Blackboard()

    def bound(node: Node, uid: str, children: list[Node]) -> Node:
        node.bind(uid=uid, node_id=uid, name=type(node).__name__, title=uid, label=uid,
                  description="", properties={}, tree_uid="main", subtree_depth=0,
                  blackboard=blackboard, record=record)
        node.adopt(children)
        return node

    leaves_bound = [bound(leaf, f"l{index}", []) for index, leaf in enumerate(leaves)]
    return Tree(bound(Sequence(), "top", leaves_bound), record=record, blackboard=blackboard,
                clock=ManualClock(), timing=timing)


def test_pre_and_post_tick_slots_of_a_users_own_node() -> None:
    counter = Counter()
    tree = _hand_tree(counter)
    calls: list[tuple[str, Status | None]] = []

    def pre(node: Node) -> Status | None:
        calls.append(("pre", None))
        return FAILURE if node.blackboard.get("skip") else None

    def post(node: Node, status: Status) -> Status | None:
        calls.append(("post", status))
        return RUNNING if node.blackboard.get("hold") else None

    counter.pre_tick, counter.post_tick = pre, post
    assert "execute" not in vars(counter)
    snapshot = tree.tick()
    assert snapshot.status is SUCCESS and counter.ticks == 1
    assert calls == [("pre", None), ("post", SUCCESS)]
    tree.blackboard["skip"] = True
    calls.clear()
    snapshot = tree.tick()
    assert snapshot.status is FAILURE and counter.ticks == 1, "a pre-tick status skips the tick"
    assert calls == [("pre", None), ("post", FAILURE)], "post-tick sees the substitute"
    assert snapshot.statuses["l0"] is FAILURE
    tree.blackboard["skip"] = False
    tree.blackboard["hold"] = True
    snapshot = tree.tick()
    assert snapshot.status is RUNNING and counter.status is RUNNING and counter.ticks == 2
    assert tree.running == [counter, tree.root], "a post-tick RUNNING keeps the node active"
    counter.pre_tick = counter.post_tick = None
    assert tree.tick().status is SUCCESS and tree.running == []
    assert counter.ticks == 3


def test_hooks_keep_a_nodes_own_callbacks_and_give_them_back() -> None:
    counter = Counter()
    tree = _hand_tree(counter)
    posts: list[Status] = []

    def own_pre(node: Node) -> Status | None:
        return None

    def own_post(node: Node, status: Status) -> Status | None:
        posts.append(status)
        return None

    counter.pre_tick, counter.post_tick = own_pre, own_post
    tree.hooks.force("l0", FAILURE)
    assert counter.pre_tick == tree.hooks.before_tick
    assert tree.tick().status is FAILURE
    assert posts == [SUCCESS], "the node's own post-tick still ran, before the force"
    tree.hooks.clear("l0")
    assert counter.pre_tick is own_pre and counter.post_tick is own_post
    assert tree.tick().status is SUCCESS
    assert posts == [SUCCESS, SUCCESS]


def test_a_users_node_is_timed_and_its_pre_tick_time_left_out() -> None:
    counter = Counter()
    tree = _hand_tree(counter, timing=True)

    def slow_pre(node: Node) -> Status | None:
        time.sleep(0.05)
        return None

    counter.pre_tick = slow_pre
    snapshot = tree.tick()
    durations = dict(zip((uid for uid, _ in snapshot.visited), snapshot.visit_durations,
                         strict=True))
    assert set(durations) == {"l0", "top"}
    assert durations["l0"] < 0.04 and durations["top"] < 0.04, durations
