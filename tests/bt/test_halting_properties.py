"""Property tests of the halting and lifecycle rules on random trees.

Random trees of composites, decorators and `Scripted` leaves are ticked with the clock moving
a random amount between ticks, and sometimes halted as a whole. After every step the lifecycle
log of the leaves and the tick's snapshot are checked against these rules:

(a) a node RUNNING after tick t and not visited in tick t+1 is halted exactly once in tick
    t+1 (a Scripted node logs one "halt"), and no node is halted that was not RUNNING;
(b) per Scripted node, "start" opens an activation, "tick" happens only inside one, and each
    activation is closed by exactly one "end:<status>" or "halt" before the next "start";
(c) every node in snapshot.active is RUNNING and its parent, if any, is active too;
(d) each node is visited at most once per tick;
(e) after tree.halt() no Scripted node is left inside an activation.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field
from typing import Any

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cyborg.bt import (
    ERROR,
    FAILURE,
    RUNNING,
    SUCCESS,
    ManualClock,
    Node,
    Status,
    TickSnapshot,
    Tree,
)
from tests.builders import LETTERS, N, Scripted, events, tree_from

MAX_DEPTH = 4
"""Depth of the deepest node below the tree's root holder (the root node has depth 1)."""
MAX_CHILDREN = 4
ROOT = "main"

COMPOSITES = ("Sequence", "Priority", "MemSequence", "MemPriority", "Parallel")
DECORATORS = ("Inverter", "ForceSuccess", "ForceFailure", "Repeater", "RepeatUntilFailure",
              "RepeatUntilSuccess", "Retry", "Limiter", "Timeout", "MaxTime", "Delay", "RunOnce")

scripts = st.lists(st.sampled_from("SFRRE"), min_size=1, max_size=5).map("".join)
"""Scripts of S, F, R, E; R is drawn twice as often so that more nodes keep running."""
loop_counts = st.sampled_from([-1, 1, 2, 3, 4])
milliseconds = st.one_of(st.sampled_from([1, 50, 100, 250, 500, 1000]),
                         st.floats(min_value=0.5, max_value=3000, allow_nan=False))


def thresholds(count: int) -> st.SearchStrategy[int]:
    return st.sampled_from([-1, *range(1, count + 1)])


@st.composite
def decorator_props(draw: st.DrawFn, name: str) -> dict[str, Any]:
    if name in ("Repeater", "RepeatUntilFailure", "RepeatUntilSuccess"):
        return {"maxLoop": draw(loop_counts)}
    if name == "Retry":
        return {"maxAttempts": draw(loop_counts)}
    if name == "Limiter":
        return {"maxLoop": draw(st.integers(min_value=0, max_value=3))}
    if name == "Timeout":
        return {"milliseconds": draw(milliseconds)}
    if name == "MaxTime":
        return {"maxTime": draw(milliseconds)}
    if name == "Delay":
        return {"milliseconds": draw(st.sampled_from([0, 50, 100, 250, 500]))}
    return {}


@st.composite
def node_specs(draw: st.DrawFn, depth: int = 1) -> N:
    """A random subtree whose root sits at ``depth``."""
    if depth >= MAX_DEPTH:
        kinds = ["leaf"]
    elif depth == 1:
        kinds = ["composite", "decorator"]
    else:  # composites twice as likely as leaves near the root, so trees grow wide enough
        kinds = ["leaf", "composite", "decorator"] + ["composite"] * (MAX_DEPTH - depth)
    kind = draw(st.sampled_from(kinds))
    if kind == "leaf":
        return N("Scripted", script=draw(scripts))
    if kind == "decorator":
        name = draw(st.sampled_from(DECORATORS))
        props = draw(decorator_props(name))
        return N(name, draw(node_specs(depth + 1)), **props)
    name = draw(st.sampled_from(COMPOSITES))
    children = draw(st.lists(node_specs(depth + 1), min_size=1, max_size=MAX_CHILDREN))
    props = {}
    if name == "Parallel":
        props = {"successThreshold": draw(thresholds(len(children))),
                 "failureThreshold": draw(thresholds(len(children)))}
    return N(name, *children, **props)


def renumber(spec: N) -> N:
    """Give the nodes short ids in pre-order (n1, n2, ...) so failures read well."""
    count = 0

    def visit(node: N) -> None:
        nonlocal count
        count += 1
        node.id = f"n{count}"
        for child in node.children:
            visit(child)

    visit(spec)
    return spec


trees = node_specs().map(renumber)

HALT = -1.0
"""An operation that halts the whole tree instead of ticking it."""
operations = st.lists(
    st.one_of(
        st.sampled_from([0.0, 0.001, 0.05, 0.1, 0.125, 0.25, 0.5, 1.0, 2.0]),
        st.floats(min_value=0.0, max_value=3.0, allow_nan=False),
        st.just(HALT),
    ),
    min_size=1,
    max_size=25,
)


# --------------------------------------------------------------------------- the checker


@dataclass
class Checker:
    """Follows a tree step by step and checks every rule after each step."""

    tree: Tree
    scripted: dict[str, Scripted] = field(default_factory=dict)
    open: set[str] = field(default_factory=set)
    """Scripted uids inside an activation (a "start" without its "end"/"halt" yet)."""
    steps: Counter[str] = field(default_factory=Counter)
    """How many times each Scripted node has been ticked: its position in its script."""
    active: set[str] = field(default_factory=set)
    """snapshot.active of the previous tick (empty after a tree halt)."""
    started: set[str] = field(default_factory=set)
    """Scripted uids that logged "start" in the last tick."""

    def __post_init__(self) -> None:
        self.scripted = {node.uid: node for node in self.tree if isinstance(node, Scripted)}

    def clock(self) -> ManualClock:
        clock = self.tree.clock
        assert isinstance(clock, ManualClock)
        return clock

    # ------------------------------------------------------------------ one tick
    def tick(self, seconds: float) -> TickSnapshot:
        self.clock().advance(seconds)
        snapshot = self.tree.tick()
        log = events(self.tree)
        visited = [uid for uid, _ in snapshot.visited]
        statuses = snapshot.statuses

        # (d) each node is visited at most once per tick; the root holder is visited last.
        assert len(visited) == len(set(visited)), f"a node visited twice: {visited}"
        assert visited[-1] == ROOT and statuses[ROOT] is snapshot.status

        self.check_halts(snapshot, set(visited))
        self.check_log(snapshot, log)
        self.check_active(snapshot)
        self.check_local_laws(snapshot)
        assert all(node.last_error is None for node in self.tree), "a node raised"
        self.active = set(snapshot.active)
        return snapshot

    def check_halts(self, snapshot: TickSnapshot, visited: set[str]) -> None:
        """(a): abandoned RUNNING nodes are halted exactly once, and only those."""
        halted = snapshot.halted
        counts = Counter(halted)
        assert all(count == 1 for count in counts.values()), f"halted twice: {halted}"
        for uid in self.active - visited:
            assert counts[uid] == 1, f"{uid} was RUNNING, not visited, and not halted"
        for uid in halted:
            status = snapshot.statuses.get(uid)
            if status is None:
                assert uid in self.active, f"{uid} halted but it was not RUNNING"
            else:  # visited in this tick: only a node that returned RUNNING may be halted
                assert status is RUNNING, f"{uid} halted after completing with {status.name}"
            assert self.tree.by_uid[uid].status is None
        # Deepest first: a node is halted after every halted node below it.
        position = {uid: index for index, uid in enumerate(halted)}
        for uid in halted:
            parent = self.tree.by_uid[uid].parent
            while parent is not None:
                if parent.uid in position:
                    assert position[parent.uid] > position[uid], f"{parent.uid} before {uid}"
                parent = parent.parent

    def check_log(self, snapshot: TickSnapshot, log: list[tuple[str, str]]) -> None:
        """(a) and (b) on the Scripted nodes' own lifecycle log."""
        statuses = snapshot.statuses
        starts_expected = {uid for uid in self.scripted
                           if uid in statuses and uid not in self.active}
        ticked: list[str] = []
        halts: list[str] = []
        started: set[str] = set()
        for event, uid in log:
            if event == "start":
                assert uid not in self.open, f"{uid} started twice without end/halt"
                assert uid not in started
                self.open.add(uid)
                started.add(uid)
            elif event == "tick":
                assert uid in self.open, f"{uid} ticked outside an activation"
                ticked.append(uid)
                self.check_script(uid, statuses[uid])
            elif event == "halt":
                assert uid in self.open, f"{uid} halted outside an activation"
                self.open.discard(uid)
                halts.append(uid)
            else:
                assert event.startswith("end:"), event
                assert uid in self.open, f"{uid} ended outside an activation"
                assert statuses[uid] is not RUNNING
                assert event == f"end:{statuses[uid].label}"
                self.open.discard(uid)
        assert started == starts_expected
        self.started = started
        assert Counter(ticked) == Counter(uid for uid in statuses if uid in self.scripted)
        assert halts == [uid for uid in snapshot.halted if uid in self.scripted]

    def check_script(self, uid: str, status: Status) -> None:
        script = self.scripted[uid].script
        step = self.steps[uid]
        self.steps[uid] += 1
        assert status is LETTERS[script[min(step, len(script) - 1)]]

    def check_active(self, snapshot: TickSnapshot) -> None:
        """(c): the active set is the RUNNING nodes, closed under parents, root first."""
        active = snapshot.active
        active_set = set(active)
        by_uid = self.tree.by_uid
        for uid in active:
            node = by_uid[uid]
            assert node.status is RUNNING, f"{uid} active but {node.status}"
            if node.parent is not None:
                assert node.parent.uid in active_set, f"{uid} active under idle parent"
        assert [by_uid[uid].index for uid in active] == sorted(by_uid[uid].index
                                                               for uid in active)
        assert active_set == {node.uid for node in self.tree if node.status is RUNNING}
        assert not active_set & set(snapshot.halted)
        assert (ROOT in active_set) == (snapshot.status is RUNNING)
        assert self.open == active_set & self.scripted.keys()
        for uid, status in snapshot.visited:
            if status is RUNNING and uid not in snapshot.halted:
                assert uid in active_set

    def check_local_laws(self, snapshot: TickSnapshot) -> None:
        """Each visited stateless node's status follows from its children's statuses."""
        statuses = snapshot.statuses
        for uid, status in snapshot.visited:
            node = self.tree.by_uid[uid]
            children = [statuses.get(child.uid) for child in node.children]
            resumed = uid in self.active  # continuing an activation from the last tick
            if node.name in ("Sequence", "Priority", "MemSequence", "MemPriority"):
                first = check_ordered(node, status, children)
                if node.name.startswith("Mem") and resumed:
                    # A memory composite resumes at the child that was RUNNING.
                    assert node.children[first].uid in self.active, f"{uid} did not resume"
                else:
                    assert first == 0, f"{uid} did not start at its first child"
            elif node.name in ("Inverter", "ForceSuccess", "ForceFailure"):
                (child,) = children
                assert child is not None
                assert status is DECORATE[node.name].get(child, child)
            elif node.name == "Parallel":
                self.check_parallel(node, status, children, resumed)

    def check_parallel(self, node: Node, status: Status, children: list[Status | None],
                       resumed: bool) -> None:
        """A Parallel ticks, in order, every child that has not completed in this activation
        (stopping at an ERROR, which it returns); once decided, no child is left RUNNING."""
        candidates = [index for index, child in enumerate(node.children)
                      if not resumed or child.uid in self.active]
        ticked = [index for index, child in enumerate(children) if child is not None]
        assert ticked == candidates[:len(ticked)], f"{node.uid} ticked {ticked}"
        if ERROR in children:
            assert children[ticked[-1]] is ERROR and status is ERROR
        else:
            assert ticked == candidates, f"{node.uid} skipped a child"
            assert status is not ERROR
        if status is not RUNNING:
            assert not any(child.status is RUNNING for child in node.children)
        elif node.status is RUNNING:  # not halted later in the tick
            assert any(child.status is RUNNING for child in node.children)


DECORATE: dict[str, dict[Status, Status]] = {
    "Inverter": {SUCCESS: FAILURE, FAILURE: SUCCESS},
    "ForceSuccess": {FAILURE: SUCCESS},
    "ForceFailure": {SUCCESS: FAILURE},
}


def check_ordered(node: Node, status: Status, children: list[Status | None]) -> int:
    """Sequence-like nodes tick a contiguous run of children that continue, and return the
    status of the one that stops them. Returns the index of the first child ticked."""
    go_on = SUCCESS if "Sequence" in node.name else FAILURE
    ticked = [index for index, child in enumerate(children) if child is not None]
    assert ticked, f"{node.uid} ticked no child"
    assert ticked == list(range(ticked[0], ticked[-1] + 1)), f"{node.uid} skipped a child"
    run = [children[index] for index in ticked]
    assert all(child is go_on for child in run[:-1])
    if run[-1] is go_on:
        assert ticked[-1] == len(children) - 1
        assert status is go_on
    else:
        assert status is run[-1]
    return ticked[0]


def halt_tree(checker: Checker) -> None:
    """(e): tree.halt() closes every open activation, deepest first, once."""
    tree = checker.tree
    expected = {node.uid for node in tree if node.status is RUNNING}
    assert expected == checker.active
    halted = [node.uid for node in tree.halt()]
    assert sorted(halted) == sorted(expected)
    assert len(halted) == len(set(halted))
    position = {uid: index for index, uid in enumerate(halted)}
    for uid in halted:
        parent = tree.by_uid[uid].parent
        if parent is not None:
            assert position[parent.uid] > position[uid]
    log = events(tree)
    assert all(event == "halt" for event, _ in log), log
    assert [uid for _, uid in log] == [uid for uid in halted if uid in checker.scripted]
    for _, uid in log:
        assert uid in checker.open
        checker.open.discard(uid)
    assert checker.open == set(), f"left inside an activation: {checker.open}"
    assert all(node.status is not RUNNING for node in tree)
    assert tree.running == []
    assert tree.halt() == []
    assert events(tree) == []
    checker.active = set()


# --------------------------------------------------------------------------- properties

SETTINGS = settings(max_examples=400, deadline=None,
                    suppress_health_check=[HealthCheck.too_slow])


@SETTINGS
@given(spec=trees, steps=operations)
def test_halting_and_lifecycle_rules_hold_on_random_trees(spec: N, steps: list[float]) -> None:
    tree = tree_from(spec)
    checker = Checker(tree)
    for step in steps:
        if step == HALT:
            halt_tree(checker)
        else:
            checker.tick(step)
    halt_tree(checker)


@SETTINGS
@given(spec=trees, advances=st.lists(st.sampled_from([0.0, 0.1, 0.25, 1.0]), min_size=2,
                                      max_size=12))
def test_tree_halt_after_any_tick_leaves_nothing_open(spec: N, advances: list[float]) -> None:
    """Ticking again after a tree halt starts every node afresh; nothing stays open."""
    tree = tree_from(spec)
    checker = Checker(tree)
    for seconds in advances:
        checker.tick(seconds)
        halt_tree(checker)
        snapshot = checker.tick(0.0)
        # Every Scripted node visited now was idle before this tick, so it started again.
        assert checker.started == snapshot.statuses.keys() & checker.scripted.keys()


@settings(max_examples=150, deadline=None)
@given(spec=trees, ticks=st.integers(min_value=1, max_value=15))
def test_root_status_is_a_status_and_errors_only_come_from_leaves(spec: N, ticks: int) -> None:
    tree = tree_from(spec)
    has_error_leaf = any(isinstance(node, Scripted) and "E" in node.script for node in tree)
    for _ in range(ticks):
        snapshot = tree.tick()
        assert isinstance(snapshot.status, Status)
        for _uid, status in snapshot.visited:
            assert status in (SUCCESS, FAILURE, RUNNING, ERROR)
            if status is ERROR:
                assert has_error_leaf
