"""behavior3 v1's data and number nodes (cyborg.bt.v1_data, cyborg.bt.v1_math).

Unit tests written against behavior3-ts's (and for Cmp and Random, behavior3lua's) documented
semantics: Check and Calculate over the blackboard, Let, Now and Clear, the array nodes (Push,
Includes, Concat, Index, RandomIndex), the object nodes (GetField, SetField), Math, Cmp and
Random; outputs rewritten (or deleted) when a node finishes, and values of the wrong kind as
ERROR.
"""

from __future__ import annotations

import random
from typing import Any

import pytest

from tests.bt.v1_samples import calc, check, let, load, n, run, seq


def test_check_and_calculate_read_the_blackboard() -> None:
    tree, clock = load(seq(check("hp > 50 && target != null"),
                           calc("hp * 2 + bonus.value", "score")),
                       hp=60, target="orc", bonus={"value": 5})
    assert run(tree, clock, 1) == "S" and tree.blackboard["score"] == 125
    tree.blackboard["hp"] = 10
    assert run(tree, clock, 1) == "F"
    del tree.blackboard["hp"]
    assert run(tree, clock, 1) == "E"
    assert "'hp' (undefined)" in str(tree.nodes[2].last_error)


def test_let_copies_the_input_or_a_fresh_json_value(caplog: pytest.LogCaptureFixture) -> None:
    tree, clock = load(seq(let([], "fresh"), n("Push", i=["fresh", "one"]),
                           let({"a": 1}, "copy", i=["source"]), let(None, "gone"),
                           let(5, "missing", i=["nothing"])),
                       one=1, source={"b": 2}, gone=3, missing=4)
    assert run(tree, clock, 2) == "SS"
    assert tree.blackboard["fresh"] == [1], "a new [] each tick, not the list pushed onto"
    assert tree.blackboard["copy"] is tree.blackboard["source"], "the input wins (oneof)"
    assert "gone" not in tree.blackboard and "missing" not in tree.blackboard
    assert caplog.text.count("'nothing', which is not set") == 1, "warned once"


def test_now_and_clear() -> None:
    tree, clock = load(seq(n("Now", o=["t"]), n("Clear", o=["old"])), old=1)
    clock.advance(41.5)
    assert run(tree, clock, 1) == "S"
    assert tree.blackboard["t"] == 42.5 and "old" not in tree.blackboard


def test_array_nodes() -> None:
    tree, clock = load(seq(
        n("Push", i=["arr", "e"]), n("Includes", i=["arr", "e"]),
        n("Invert", n("Includes", i=["arr", "absent"])),
        n("Invert", n("Includes", i=["arr", "true_"])),
        n("Concat", i=["arr", "more"], o=["both"]),
        n("Index", args={"index": 1}, i=["both", ""], o=["second"]),
        n("Index", args={"index": 0}, i=["both", "at"], o=["third"])),
        arr=[1], e=2, more=[3], at=2, true_=True)
    assert run(tree, clock, 1) == "S"
    assert tree.blackboard["arr"] == [1, 2] and tree.blackboard["both"] == [1, 2, 3]
    assert (tree.blackboard["second"], tree.blackboard["third"]) == (2, 3)
    tree, clock = load(n("Index", args={"index": 5}, i=["arr", ""], o=["v"]), arr=[1], v=0)
    assert run(tree, clock, 1) == "F" and "v" not in tree.blackboard, "output deleted"
    for bad in (n("Push", i=["arr", "e"]), n("Includes", i=["arr", "e"]),
                n("Concat", i=["arr", "arr"], o=["x"]), n("Index", i=["arr", ""], o=["x"])):
        tree, clock = load(bad, arr="not a list", e=1)
        assert run(tree, clock, 1) == "E", bad["name"]
    assert "must hold an array (a list), not 'not a list'" in str(tree.nodes[1].last_error)


def test_index_needs_an_index() -> None:
    tree, clock = load(n("Index", i=["arr", ""], o=["v"]), arr=[1])
    assert run(tree, clock, 1) == "E"
    assert "the index must be a whole number, not undefined" in str(tree.nodes[1].last_error)


def test_object_nodes() -> None:
    tree, clock = load(seq(
        n("GetField", args={"field": "x"}, i=["obj", ""], o=["x"]),
        n("GetField", i=["obj", "key"], o=["y"]),
        n("SetField", args={"field": "w", "value": [1]}, i=["obj", "", ""]),
        n("SetField", args={"field": "x"}, i=["obj", "", ""]),
        n("SetField", i=["obj", "key", "v"]),
        n("SetField", args={"field": "1", "value": "b"}, i=["arr", "", ""]),
        n("SetField", args={"value": "c"}, i=["arr", "two", ""])),
        obj={"x": 1, "y": 2}, key="y", v=9, arr=["a", "-"], two=2)
    assert run(tree, clock, 1) == "S"
    assert (tree.blackboard["x"], tree.blackboard["y"]) == (1, 2)
    assert tree.blackboard["obj"] == {"y": 9, "w": [1]}
    assert tree.blackboard["arr"] == ["a", "b", "c"]
    tree, clock = load(n("GetField", args={"field": "z"}, i=["obj", ""], o=["z"]), obj={}, z=1)
    assert run(tree, clock, 1) == "F" and "z" not in tree.blackboard
    tree, clock = load(n("SetField", args={"field": "z"}, i=["obj", "", ""]), obj=3)
    assert run(tree, clock, 1) == "E"


def test_random_index_picks_an_element_and_its_index() -> None:
    random.seed(3)
    tree, clock = load(n("RandomIndex", i=["arr"], o=["v", "at"]), arr=["a", "b", "c"])
    seen = set()
    for _ in range(30):
        assert run(tree, clock, 1) == "S"
        value, index = tree.blackboard["v"], tree.blackboard["at"]
        assert ["a", "b", "c"][index] == value
        seen.add(value)
    assert seen == {"a", "b", "c"}
    tree, clock = load(n("RandomIndex", i=["arr"], o=["v", "at"]), arr=[], v=1)
    assert run(tree, clock, 1) == "F" and "v" not in tree.blackboard


@pytest.mark.parametrize(("args", "inputs", "expected"), [
    ({"op": "sum"}, [1, 2, 3.5], 6.5), ({"op": "max", "value1": 10}, [1, 20], 20),
    ({"op": "min"}, [4, -1, 2], -1), ({"op": "round"}, [-2.5], -2), ({"op": "round"}, [2.5], 3),
    ({"op": "pow", "value1": 2, "value2": 10}, [], 1024), ({"op": "sign"}, [-3], -1),
    ({"op": "average"}, [1, 2], 1.5), ({"op": "product"}, [2, 3, 4], 24),
    ({"op": "atan2"}, [0, 1], 0), ({"op": "abs", "value1": -2}, [], 2),
    ({"op": "floor"}, ["2.7"], 2), ({"op": "randInt", "value1": 4, "value2": 4}, [], 4),
    ({"op": "abs"}, [1, 2], None), ({"op": "randFloat"}, [5, 1], None), ({"op": "max"}, [], None),
    ({"op": "sqrt"}, [-1], "E"), ({"op": "log"}, ["x"], "E"),
])
def test_math(args: dict[str, Any], inputs: list[Any], expected: Any) -> None:
    names = [f"v{k}" for k in range(len(inputs))]
    tree, clock = load(n("Math", args=args, i=names, o=["result"]),
                       **dict(zip(names, inputs, strict=True)), result="old")
    status = run(tree, clock, 1)
    if expected == "E":
        assert status == "E" and "(NaN)" in str(tree.nodes[1].last_error)
    elif expected is None:
        assert status == "F" and "result" not in tree.blackboard
    else:
        assert status == "S" and tree.blackboard["result"] == pytest.approx(expected)


def test_math_random_ops_stay_in_range() -> None:
    tree, clock = load(seq(n("Math", args={"op": "random"}, o=["r"]),
                           n("Math", args={"op": "randInt", "value1": 1, "value2": 3}, o=["i"]),
                           n("Math", args={"op": "randFloat"}, i=["lo", "hi"], o=["f"])),
                       lo=-1, hi=1)
    for _ in range(20):
        assert run(tree, clock, 1) == "S"
        assert 0 <= tree.blackboard["r"] < 1 and tree.blackboard["i"] in (1, 2, 3)
        assert -1 <= tree.blackboard["f"] <= 1


@pytest.mark.parametrize(("args", "inputs", "expected"), [
    ({"lt": 50}, {"hp": 20}, "S"), ({"lt": 50}, {"hp": 50}, "F"), ({"ge": 50}, {"hp": 50}, "S"),
    ({"gt": 1, "lt": 0}, {"hp": 2}, "S"),  # the first comparison set decides
    ({"eq": 3}, {"hp": 3.0}, "S"), ({"le": 1}, {}, "F"),  # unset: FAILURE
    ({"gt": 1}, {"hp": "x"}, "E"),
])
def test_cmp(args: dict[str, Any], inputs: dict[str, Any], expected: str) -> None:
    tree, clock = load(n("Cmp", args=args, i=["hp"]), **inputs)
    assert run(tree, clock, 1) == expected


def test_cmp_evaluates_its_value_expression_when_no_input_is_bound() -> None:
    tree, clock = load(n("Cmp", args={"value": "hp * 2", "gt": 50}, i=[""]), hp=30)
    assert run(tree, clock, 1) == "S"


def test_random_writes_a_number_between_min_and_max() -> None:
    tree, clock = load(seq(n("Random", args={"min": 1, "max": 3}, o=["r"]),
                           n("Random", args={"min": 0, "max": 9, "floor": True}, i=["lo", ""],
                             o=["f"])), lo=5)
    for _ in range(20):
        assert run(tree, clock, 1) == "S"
        assert 1 <= tree.blackboard["r"] <= 3
        assert tree.blackboard["f"] in range(5, 10)
    tree, clock = load(n("Random", o=["r"]))
    assert run(tree, clock, 1) == "E"
