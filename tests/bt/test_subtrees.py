"""Subtrees: referenced by tree id, nested to any depth, an independent instance per use."""

from __future__ import annotations

import json

import pytest

from cyborg.bt import ManualClock, Status, Subtree, TreeLoadError, loads_tree
from tests.builders import N, events, project_json, registry, tree_json


def _project() -> str:
    leaf = tree_json(N("MemSequence", N("Scripted", id="work", script="RS"), id="leafroot"),
                     tree_id="leaf", title="Leaf tree")
    middle = tree_json(N("MemSequence", N("leaf", id="m1"), N("leaf", id="m2"), id="midroot"),
                       tree_id="middle", title="Middle tree")
    top = tree_json(N("MemSequence", N("middle", id="r1"), N("leaf", id="r2"), id="toproot"),
                    tree_id="top", title="Top tree")
    return project_json([top, middle, leaf], selected="top")


def test_each_reference_is_an_independent_instance() -> None:
    tree = loads_tree(_project(), registry=registry(), clock=ManualClock())
    works = [node for node in tree if node.node_id == "work"]
    assert [node.uid for node in works] == ["r1/m1/work", "r1/m2/work", "r2/work"]
    assert len({id(node) for node in works}) == 3
    assert len({id(node.memory) for node in works}) == 3
    # The first instance runs, then succeeds; the others start fresh, unaffected.
    statuses = [tree.tick().status for _ in range(4)]
    assert statuses == [Status.RUNNING] * 3 + [Status.SUCCESS]
    assert [event for event in events(tree) if event[0] == "start"] == [
        ("start", "r1/m1/work"), ("start", "r1/m2/work"), ("start", "r2/work")]


def test_stable_ids_depths_and_tree_nodes() -> None:
    tree = loads_tree(_project(), registry=registry(), clock=ManualClock())
    depth = {node.uid: node.subtree_depth for node in tree}
    assert depth["top"] == 0 and depth["toproot"] == 0
    assert depth["r1"] == 0 and depth["r1/midroot"] == 1
    assert depth["r1/m1"] == 1 and depth["r1/m1/leafroot"] == 2 and depth["r1/m1/work"] == 2
    assert depth["r2"] == 0 and depth["r2/leafroot"] == 1
    ref = tree.by_uid["r1"]
    assert ref.category.value == "tree"
    assert ref.label == "Middle tree"
    assert isinstance(ref, Subtree) and ref.tree_id == "middle"
    snapshot = tree.tick()
    assert snapshot.active == ["top", "toproot", "r1", "r1/midroot", "r1/m1",
                               "r1/m1/leafroot", "r1/m1/work"]


def test_reference_cycle_is_an_error_naming_the_trees() -> None:
    a = tree_json(N("Sequence", N("b", id="to-b"), id="aroot"), tree_id="a", title="Tree A")
    b = tree_json(N("Sequence", N("c", id="to-c"), id="broot"), tree_id="b", title="Tree B")
    c = tree_json(N("Sequence", N("a", id="to-a"), id="croot"), tree_id="c", title="Tree C")
    with pytest.raises(TreeLoadError) as caught:
        loads_tree(project_json([a, b, c], selected="a"), registry=registry())
    message = str(caught.value)
    assert "cycle" in message
    assert "'Tree A' -> 'Tree B' -> 'Tree C' -> 'Tree A'" in message
    assert "to-a" in message


def test_self_reference_is_a_cycle() -> None:
    a = tree_json(N("Sequence", N("a", id="self"), id="aroot"), tree_id="a", title="Loop")
    with pytest.raises(TreeLoadError, match=r"'Loop' -> 'Loop'"):
        loads_tree(project_json([a]), registry=registry())


def test_deep_nesting() -> None:
    trees = []
    for level in range(30):
        child = N(f"level{level + 1}", id=f"ref{level}") if level < 29 else N("Succeeder", id="x")
        trees.append(tree_json(N("Sequence", child, id=f"root{level}"), tree_id=f"level{level}",
                               title=f"Level {level}"))
    tree = loads_tree(json.dumps(json.loads(project_json(trees, selected="level0"))),
                      registry=registry())
    leaf = next(node for node in tree if node.node_id == "x")
    assert leaf.subtree_depth == 29
    assert leaf.uid.count("/") == 29
    assert tree.tick().status is Status.SUCCESS


def test_tree_scope_memory_is_per_instance() -> None:
    tree = loads_tree(_project(), registry=registry(), clock=ManualClock())
    first = tree.by_uid["r1/m1/work"]
    second = tree.by_uid["r2/work"]
    first.tree_memory["seen"] = 1
    assert "seen" not in second.tree_memory
    assert tree.blackboard.as_dict()["trees"]["r1/m1"] == {"seen": 1}
