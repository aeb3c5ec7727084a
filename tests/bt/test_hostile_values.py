"""Hostile values in tree files (issue 19, items 8 and 10): numbers and text.

Numbers too large for a float, with thousands of digits, NaN or infinite where a node does not
allow them, and values nested too deeply are located errors (measured in linear time, even in
malformed text); lone surrogates are located errors, and whatever text reaches the DOT writer
or a problem can be printed.
"""

from __future__ import annotations

import math
from typing import Any

import pytest

from cyborg.bt import Blackboard, ManualClock, Problem, Succeeder, Tree, loads_tree
from cyborg.bt import limits as bt_limits
from cyborg.bt.node import TickRecord
from tests.bt.hostile_helpers import Below, _bounded, _errors, _one, _registry, _v1


# ---------------------------------------------------------------------------- numbers
@pytest.mark.parametrize("value", ["9" * 400, "-" + "9" * 400, "1e400", "-1e400"])
def test_numbers_too_large_for_a_float_are_located_errors(value: str) -> None:
    text = _one("Wait", {}).replace('"properties": {}',
                                    f'"properties": {{"milliseconds": {value}}}')
    (error,) = _errors(lambda: loads_tree(text))
    assert error.node_id == "x" and error.field == "milliseconds"
    assert "finite" in error.message or "too large" in error.message


def test_a_5000_digit_number_is_a_located_error() -> None:
    text = _one("Wait", {}).replace('"properties": {}', '"properties":\n{"milliseconds": '
                                    + "9" * 5000 + "}")
    (error,) = _errors(lambda: loads_tree(text))
    assert error.line == 2 and "digits" in error.message


def test_a_400_digit_whole_number_fits_an_int_property() -> None:
    tree = loads_tree(_one("Below", {"count": 10 ** 400}), registry=_registry())
    (node,) = [n for n in tree.nodes if isinstance(n, Below)]
    assert node.count == 10 ** 400


@pytest.mark.parametrize("value", [float("nan"), "NaN", "nan", float("inf"), "-Infinity"])
def test_nan_and_infinity_are_refused_in_numeric_properties(value: object) -> None:
    for name, key in (("Wait", "milliseconds"), ("Timeout", "milliseconds")):
        text = _one(name, {key: value})
        errors = _errors(lambda: loads_tree(text))  # noqa: B023 (called at once)
        assert any(e.field == key and "finite" in e.message for e in errors), errors
    (error,) = _errors(lambda: loads_tree(_one("Below", {"radius": value}),
                                          registry=_registry()))
    assert error.field == "radius"


def test_nan_seconds_in_a_v1_wait_is_refused() -> None:
    errors = _errors(lambda: loads_tree(_v1({"id": 1, "name": "Wait", "args": {"time": "nan"}})))
    assert any("finite" in e.message for e in errors)


def test_infinity_is_accepted_where_the_node_defaults_to_it() -> None:
    for value in (float("inf"), "Infinity", "inf", -math.inf):
        tree = loads_tree(_one("Below", {"below": value}), registry=_registry())
        (node,) = [n for n in tree.nodes if isinstance(n, Below)]
        assert math.isinf(node.below)
    errors = _errors(lambda: loads_tree(_one("Below", {"below": "nan"}), registry=_registry()))
    assert errors[0].field == "below"


def test_property_values_nested_too_deeply_are_located_errors() -> None:
    value: Any = 1
    for _ in range(40):
        value = [value]
    errors = _errors(lambda: loads_tree(_one("Below", {"extra": value}),
                                        registry=_registry()))
    assert any(e.field == "extra" and "more than 32 levels" in e.message for e in errors)
    deep = "[" * 500 + "1" + "]" * 500
    text = _one("Below", {}).replace('"properties": {}', '"properties":\n {"v": ' + deep + "}")
    (error,) = _errors(lambda: loads_tree(text, registry=_registry()))
    # the tree's own properties are an object 2 levels deep, so the cap is passed by the
    # value's (max_nesting - 1)-th bracket; the first is in column 8, after ' {"v": '
    assert (error.line, error.column) == (2, 7 + bt_limits.Limits().max_nesting - 1)
    assert "nested more deeply than" in error.message


def test_measuring_the_nesting_of_malformed_text_takes_linear_time() -> None:
    """Brackets inside an unterminated string, after many escaped quotes: a scan that retried
    from every quote would be quadratic (12 s for 60 kB)."""
    text = '"' + '\\"[' * 300_000
    errors = _errors(lambda: _bounded(lambda: loads_tree(text), 5))
    assert "malformed JSON" in errors[0].message


def test_a_title_showing_a_huge_property_is_cut_short() -> None:
    text = _one("Below", {"x": list(range(100_000)), "y": "z" * 10}, title="<x> <y>")
    tree = loads_tree(text, registry=_registry())
    (node,) = [n for n in tree.nodes if isinstance(n, Below)]
    assert node.label.endswith("...] zzzzzzzzzz") and len(node.label) < 100


# ---------------------------------------------------------------------------- text
def test_a_lone_surrogate_is_a_located_error() -> None:
    text = _one("Succeeder", {}, title="MARKER").replace("MARKER", "a\\ud800b")
    (error,) = _errors(lambda: loads_tree(text))
    assert error.line == 1 and "surrogate" in error.message
    paired = _one("Succeeder", {}, title="MARKER").replace("MARKER", "\\ud83e\\udd16 \\\\ud800")
    tree = loads_tree(paired)
    assert tree.nodes[1].title == "\U0001f916 \\ud800"


def test_a_lone_surrogate_in_a_v1_file_and_in_text_given_directly() -> None:
    text = _v1({"id": 1, "name": "JustSuccess", "desc": "MARKER"}).replace("MARKER", "\\udc00")
    assert "surrogate" in _errors(lambda: loads_tree(text))[0].message
    raw = _one("Succeeder", {}, title="a\ud800b")  # json.dumps escapes it
    assert "surrogate" in _errors(lambda: loads_tree(raw.replace("\\ud800", "\ud800")))[0].message


def test_dot_and_problems_print_whatever_text_they_are_given() -> None:
    record, blackboard = TickRecord(), Blackboard()
    node = Succeeder()
    node.bind(uid="a\ud800", node_id="a", name="Succeeder", title="t\udfff", label="t\udfff",
              description="", properties={}, tree_uid="", subtree_depth=0,
              blackboard=blackboard, record=record)
    tree = Tree(node, record=record, blackboard=blackboard, clock=ManualClock())
    tree.to_dot().encode("utf-8")
    str(Problem("bad \ud800", "file\udcff.json", 1)).encode("utf-8")
