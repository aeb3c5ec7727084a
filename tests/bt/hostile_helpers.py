"""Helpers for the hostile tree tests (tests/bt/test_hostile_*.py).

Test-only nodes (Below, whose property defaults to infinity; Deep, which measures the stack),
builders of hostile tree files (chains of nodes, trees doubling their references, single nodes,
v1 files), a check that loading failed with errors that are all located, and a runner that
fails a call, instead of hanging, when it takes too long.
"""

from __future__ import annotations

import json
import math
import sys
import threading
from collections.abc import Callable
from typing import Any

import pytest

from cyborg.bt import Action, Condition, Problem, Status, TreeLoadError, default_registry
from cyborg.bt.registry import NodeRegistry


class Below(Condition):
    """A condition with a property that explicitly allows infinity (its default is inf)."""

    def __init__(self, below: float = math.inf, radius: float = 0.5, count: int = 0) -> None:
        self.below, self.radius, self.count = below, radius, count

    def tick(self) -> Status:
        return Status.SUCCESS


class Deep(Action):
    """Records how deep the stack is when it ticks; raises when asked."""

    frames = 0

    def __init__(self, fail: bool = False) -> None:
        self.fail = fail

    def tick(self) -> Status:
        frame: Any = sys._getframe()
        count = 0
        while frame is not None:
            count, frame = count + 1, frame.f_back
        Deep.frames = max(Deep.frames, count)
        if self.fail:
            raise RuntimeError("deep failure")
        return Status.SUCCESS


def _registry() -> NodeRegistry:
    registry = default_registry(entry_points=False)
    registry.add(Below)
    registry.add(Deep)
    return registry


def _tree(tree_id: str, nodes: dict[str, Any], root: str) -> dict[str, Any]:
    return {"id": tree_id, "title": tree_id, "description": "", "root": root,
            "properties": {}, "nodes": nodes}


def _chain(levels: int, name: str = "Inverter", leaf: str = "Succeeder",
           leaf_props: dict[str, Any] | None = None) -> dict[str, Any]:
    """``levels`` nodes named ``name``, each the parent of the next, over one leaf."""
    nodes: dict[str, Any] = {}
    link = "child" if name == "Inverter" else "children"
    for level in range(levels):
        target = f"n{level + 1}"
        nodes[f"n{level}"] = {"id": f"n{level}", "name": name,
                              link: target if link == "child" else [target]}
    nodes[f"n{levels}"] = {"id": f"n{levels}", "name": leaf, "properties": leaf_props or {}}
    return {"scope": "tree", **_tree("main", nodes, "n0")}


def _one(name: str, properties: dict[str, Any], title: str = "") -> str:
    node = {"id": "x", "name": name, "title": title or name, "properties": properties}
    return json.dumps({"scope": "tree", **_tree("main", {"x": node}, "x")})


def _errors(call: Callable[[], object]) -> list[Problem]:
    with pytest.raises(TreeLoadError) as caught:
        call()
    errors = [p for p in caught.value.problems if p.is_error]
    assert errors
    for problem in caught.value.problems:
        assert_located(problem)
    return errors


def assert_located(problem: Problem) -> None:
    """A problem names its file and where in it: a line, a node id or a field."""
    assert problem.source, problem
    assert problem.line is not None or problem.node_id is not None \
        or problem.field is not None, problem
    str(problem).encode("utf-8")  # printable, whatever the file held


def _bounded(call: Callable[[], object], seconds: float = 10.0) -> object:
    """Run ``call`` on a daemon thread; fail (instead of hanging) if it takes too long."""
    outcome: list[object] = []

    def run() -> None:
        try:
            outcome.append(call())
        except BaseException as exc:  # handed back to the test
            outcome.append(exc)

    thread = threading.Thread(target=run, daemon=True)
    thread.start()
    thread.join(seconds)
    assert not thread.is_alive(), f"still running after {seconds} s"
    if isinstance(outcome[0], BaseException):
        raise outcome[0]
    return outcome[0]


def _v1(root: dict[str, Any], **top: Any) -> str:
    return json.dumps({"name": "t", "root": root, **top})


def _doubling(levels: int) -> str:
    """``levels`` trees, each referencing the next twice: 2^levels instances of the last."""
    trees = []
    for i in range(levels):
        nodes = {"s": {"id": "s", "name": "Sequence", "children": ["a", "b"]},
                 "a": {"id": "a", "name": f"t{i + 1}"}, "b": {"id": "b", "name": f"t{i + 1}"}}
        trees.append(_tree(f"t{i}", nodes, "s"))
    trees.append(_tree(f"t{levels}", {"r": {"id": "r", "name": "Succeeder"}}, "r"))
    return json.dumps({"trees": trees, "selectedTree": "t0"})
