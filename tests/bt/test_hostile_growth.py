"""Values an expression grows through a Repeat stay bounded: numbers are doubles, texts end at
MAX_TEXT, and a tick that grows them ends (a Calculate once held the runner in one
multiplication of integers with billions of digits, or built gigabytes of text)."""

from __future__ import annotations

import logging
import math
import tracemalloc
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cyborg.bt.expressions import MAX_TEXT
from cyborg.bt.js_values import SAFE_INTEGER
from cyborg.bt.limits import MAX_VALUE_SIZE
from tests.bt.v1_samples import load, run

SEEDS = st.one_of(st.integers(-10**6, 10**6), st.floats(allow_nan=False), st.sampled_from(
    ["'x'", "'ab'", "''", "3", "0.5", "-7", "1e300", "9007199254740991"]).map(str))
GROWTH = ["v {op} v", "v {op} v {op} v", "(v {op} 2) {op} v", "v {op} v {op} 1"]
OPERATORS = ["+", "*", "-", "<<", "/", "%", "|"]


def _bounded(value: Any) -> bool:
    if isinstance(value, bool) or value is None or isinstance(value, float):
        return True
    if isinstance(value, int):
        return -SAFE_INTEGER <= value <= SAFE_INTEGER
    return isinstance(value, str | list) and len(value) <= MAX_TEXT


@settings(max_examples=60, deadline=None)
@given(seed=SEEDS, growth=st.sampled_from(GROWTH), op=st.sampled_from(OPERATORS),
       count=st.integers(1, 60))
def test_values_grown_through_a_repeat_stay_bounded(seed: Any, growth: str, op: str,
                                                    count: int) -> None:
    literal = seed if isinstance(seed, str) else repr(seed)
    if isinstance(seed, float) and not math.isfinite(seed):
        literal = "Infinity" if seed > 0 else "-Infinity"
    grow = {"id": "2", "name": "Calculate",
            "args": {"value": f"v ? {growth.format(op=op)} : {literal}"}, "output": ["v"]}
    tree, clock = load({"id": "1", "name": "Repeat", "args": {"count": count},
                        "children": [grow]})
    status = run(tree, clock, 1)  # ends: no multiplication or join without bound
    assert status in ("S", "F", "E")
    assert _bounded(tree.blackboard.get("v")), repr(tree.blackboard.get("v"))[:80]


def _calculate(expression: str) -> dict[str, Any]:
    return {"id": "3", "name": "Calculate", "args": {"value": expression}, "output": ["v"]}


BOMBS = {  # the node that grows v, and v's first value
    "squares": (_calculate("v * v"), 3),
    "doubled text": (_calculate("v + v"), "x"),
    "doubled list": ({"id": "3", "name": "Concat", "input": ["v", "v"], "output": ["v"]},
                     [1, 2, 3, 4]),
}


def _bomb(name: str) -> dict[str, Any]:
    grow, seed = BOMBS[name]
    return {"id": "1", "name": "Sequence", "children": [
        {"id": "2", "name": "Let", "args": {"value": seed}, "output": ["v"]},
        {"id": "4", "name": "Repeat", "args": {"count": 40}, "children": [grow]}]}


@pytest.mark.parametrize("bomb", BOMBS)
def test_a_tree_bomb_ends_its_tick_within_bounded_memory(bomb: str) -> None:
    """Each reached 1.8-2.1 GB (or never ended) in one tick of a Repeat of 40."""
    tree, clock = load(_bomb(bomb))
    tracemalloc.start()
    try:
        status = run(tree, clock, 1)
        _now, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak < 200 * 2**20, f"{peak / 2**20:.0f} MiB at the peak"
    assert _bounded(tree.blackboard.get("v"))
    assert status in ("S", "E")


def test_a_node_writing_a_value_past_the_limit_returns_error_naming_its_output(
        caplog: pytest.LogCaptureFixture) -> None:
    tree, clock = load(_bomb("doubled list"))
    with caplog.at_level(logging.ERROR, "cyborg.bt"):
        assert run(tree, clock, 1) == "E"
    assert len(tree.blackboard.get("v")) == MAX_VALUE_SIZE
    assert "node 3 (Concat" in caplog.text and "output 'result' would hold 2,097,152 items, " \
        f"more than the {MAX_VALUE_SIZE:,} a blackboard value may hold" in caplog.text


def test_push_stops_at_the_limit(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr("cyborg.bt.v1_data.MAX_VALUE_SIZE", 5)
    root = {"id": "1", "name": "Sequence", "children": [
        {"id": "2", "name": "Let", "args": {"value": []}, "output": ["v"]},
        {"id": "4", "name": "Repeat", "args": {"count": 40}, "children": [
            {"id": "3", "name": "Push", "input": ["v", "v"]}]}]}
    tree, clock = load(root)
    assert run(tree, clock, 1) == "E"
    assert len(tree.blackboard.get("v")) == 5
