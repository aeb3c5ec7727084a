"""Values an expression grows through a Repeat stay bounded: numbers are doubles, texts end at
MAX_TEXT, and a tick that grows them ends (a Calculate once held the runner in one
multiplication of integers with billions of digits, or built gigabytes of text)."""

from __future__ import annotations

import math
from typing import Any

from hypothesis import given, settings
from hypothesis import strategies as st

from cyborg.bt.expressions import MAX_TEXT
from cyborg.bt.js_values import SAFE_INTEGER
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
    return isinstance(value, str) and len(value) <= MAX_TEXT


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
