"""Expressions of behavior3 v1's args (cyborg.bt.expressions), evaluated like JavaScript.

Unit tests written against behavior3-ts's documented semantics (the fact sheet, section 7):
operators and precedence, members of dicts, lists and strings, strict equality and
short-circuits; syntax errors located when the text is parsed, evaluation errors that name the
operand and what it held; no way to Python's attributes or builtins, and hostile texts refused
at once without recursion errors.
"""

from __future__ import annotations

import math
import time
from typing import Any

import pytest

from cyborg.bt.expressions import MAX_DEPTH, MAX_LENGTH, MAX_TEXT, Expression, ExpressionError


@pytest.mark.parametrize(("text", "expected"), [
    ("1 + 2 * 3", 7), ("(1 + 2) * 3", 9), ("2 + 3 * 4 - 6 / 3", 12), ("10 - 4 - 3", 3),
    ("2 * 3 % 4", 2), ("-2 * -3", 6), ("- -2", 2), ("+true + 1", 2), ("!0 == true", True),
    ("1 < 2 == true", True), ("1 + 2 < 4 && 3 > 2", True), ("1 || 0 && 0", 1),
    ("0 ? 1 : 2 ? 3 : 4", 3), ("1 ? 0 ? 5 : 6 : 7", 6), ("1 | 2 ^ 3 & 5", 3),
    ("1 << 2 + 1", 8), ("-1 >>> 28", 15), ("-16 >> 2", -4), ("1 << 31", -2147483648),
    ("~5", -6), ("~-1", 0), ("7 & 3 == 3", 1), ("5 / 2", 2.5), ("-7 % 3", -1), ("7 % -3", 1),
    ("1 / 0", float("inf")), ("-1 / 0", float("-inf")), ("2 === 2.0", True),
    ("'a' != \"a\"", False), ("'ab' < 'b'", True), ("'n' + 1 + true", "n1true"),
    ("'say \\'hi\\''", "say 'hi'"), ("1e3 + 0.5", 1000.5), ("Infinity > 1e308", True),
    ("NaN == NaN", False), ("null == undefined", True), ("2 !== 3", True),
])
def test_operators_follow_javascripts_precedence(text: str, expected: Any) -> None:
    assert Expression(text).evaluate({}) == expected


def test_identifiers_read_variables_and_members_read_dicts_lists_and_strings() -> None:
    variables = {"arr": [{"x": 1}, 5], "a": {"y": 2, "1": "one", "list": [7, 8]}, "s": "hey",
                 "flag": False}
    values = {
        "arr[0].x + a.y": 3, "a['y']": 2, "a[1]": "one", "a.list[1]": 8, "arr.length": 2,
        "s.length": 3, "s[1]": "e", "arr[5]": None, "arr[-1]": None, "arr[0.5]": None,
        "a.missing": None, "unset": None, "a.list['0']": 7, "flag ? 1 : 2": 2,
    }
    for text, expected in values.items():
        assert Expression(text).evaluate(variables) == expected, text


def test_logical_operators_short_circuit_and_return_an_operand() -> None:
    # the right side would raise (a member of undefined) if it were evaluated
    assert Expression("target && target.hp > 0").evaluate({}) is None
    assert Expression("ready || target.hp").evaluate({"ready": "yes"}) == "yes"
    assert Expression("0 || ''").evaluate({}) == ""
    assert Expression("l ? 1 : 2").evaluate({"l": []}) == 1  # an empty list is true
    assert Expression("x ? 1 : y.z").evaluate({"x": 1}) == 1  # the other branch is not run
    with pytest.raises(ExpressionError):
        Expression("x ? 1 : y.z").evaluate({"x": 0})


def test_equality_is_strict_as_in_behavior3_ts() -> None:
    table = {"1 == true": False, "1 == '1'": False, "0 == ''": False, "a == b": False,
             "a == a": True, "n == 3": True, "t == true": True}
    variables = {"a": [1], "b": [1], "n": 3.0, "t": True}
    for text, expected in table.items():
        assert Expression(text).evaluate(variables) is expected, text


@pytest.mark.parametrize(("text", "fragments"), [
    ("1 +", ["in '1 +'", "expected a value", "column 4"]),
    ("a = 1", ["'=' at column 3 would assign", "'=='"]),
    ("(1 + 2", ["expected ')'", "the end"]),
    ("'open", ["string starting at column 1 is not closed"]),
    ("2abc", ["'2abc'", "neither a number nor a name"]),
    ("a..b", ["expected a field name after '.'"]),
    ("a # b", ["unexpected character '#'"]),
    ("1 2", ["unexpected 2", "operator missing"]),
    ("f(1)", ["unexpected '('"]),  # no calls: nothing but values and operators
    ("", ["empty"]), ("   ", ["empty"]),
    ("x" * (MAX_LENGTH + 1), [f"at most {MAX_LENGTH}"]),
])
def test_syntax_errors_are_caught_when_parsed_with_a_located_message(
        text: str, fragments: list[str]) -> None:
    with pytest.raises(ExpressionError) as caught:
        Expression(text)
    for fragment in fragments:
        assert fragment in str(caught.value), str(caught.value)


@pytest.mark.parametrize(("text", "variables", "fragments"), [
    ("hp > 50", {}, ["'>' needs a number", "'hp' (undefined)"]),
    ("target.hp", {}, ["cannot read 'hp' of 'target' (undefined)"]),
    ("t.x", {"t": 3}, ["cannot read 'x' of 't' (3)"]),
    ("o.__class__", {"o": object()}, ["cannot read '__class__' of 'o' (an object)"]),
    ("'x' + 2.5 + null", {}, ["joins a string only with", "undefined"]),
    ("xs + 1", {"xs": [1]}, ["'+' needs a number", "'xs' (a list)"]),
    ("s < 1", {"s": "a"}, ["compares two numbers or two strings", "'s' ('a') and 1"]),
    ("'a' + m", {"m": {}}, ["joins a string only with", "'m' (an object)"]),
    ("-name", {"name": "x"}, ["'-' needs a number", "'name' ('x')"]),
])
def test_evaluation_errors_name_the_operand_and_what_it_held(
        text: str, variables: dict[str, Any], fragments: list[str]) -> None:
    with pytest.raises(ExpressionError) as caught:
        Expression(text).evaluate(variables)
    for fragment in fragments:
        assert fragment in str(caught.value), str(caught.value)


def test_python_attributes_and_builtins_are_out_of_reach() -> None:
    """Identifiers are only ever looked up in the variables; a member is only ever a dict
    key, a list element or ``length``: never a Python attribute, never a call."""
    for text in ("__import__('os')", "open('x')", "a.__class__.__bases__", "(1).real"):
        with pytest.raises(ExpressionError):
            Expression(text).evaluate({"a": {}})
    assert Expression("a.__class__").evaluate({"a": {}}) is None  # a missing key, no more
    assert Expression("__builtins__").evaluate({}) is None


@pytest.mark.parametrize("text", [
    "(" * 600 + "1" + ")" * 600, "!" * 999 + "x", "-" * 999 + "1", "1" + " + 1" * 300,
    "a" + ".b" * 400, "a" + "[0]" * 300, "x ? " * 240 + "1" + " : 2" * 240,
    "((((((((((" * 99, "[" * 999,
])
def test_hostile_expressions_are_refused_at_once_without_recursion_errors(text: str) -> None:
    started = time.perf_counter()
    with pytest.raises(ExpressionError) as caught:
        Expression(text[:MAX_LENGTH])
    assert time.perf_counter() - started < 0.5
    message = str(caught.value)
    assert f"nested more than {MAX_DEPTH} levels" in message or "expected" in message


def test_the_deepest_accepted_expression_still_evaluates() -> None:
    text = "(" * (MAX_DEPTH - 1) + "1" + ")" * (MAX_DEPTH - 1)
    assert Expression(text).evaluate({}) == 1
    chain = "1" + " + 1" * (MAX_DEPTH - 1)
    assert Expression(chain).evaluate({}) == MAX_DEPTH


def test_huge_numbers_are_doubles_as_in_javascript() -> None:
    big = {"x": 10 ** 400}
    assert Expression("x / 3").evaluate(big) == math.inf
    assert Expression("x * x > 0").evaluate(big) is True
    assert Expression("-x").evaluate(big) == -math.inf
    assert Expression("9007199254740993").evaluate({}) == 2.0 ** 53  # the nearest double
    assert Expression("9007199254740992 + 1").evaluate({}) == 2.0 ** 53
    assert Expression("3 * 3").evaluate({}) == 9 and isinstance(
        Expression("3 * 3").evaluate({}), int), "small integers stay integers, shown as 9"


def test_squaring_over_and_over_stays_one_machine_number() -> None:
    """``n ? n * n : 3`` in a Repeat of 40 held the interpreter in one multiplication of
    integers with billions of digits; as doubles it reaches Infinity in a few steps."""
    square = Expression("n ? n * n : 3")
    n: Any = None
    for _ in range(40):
        n = square.evaluate({"n": n})
    assert n == math.inf


def test_a_text_that_doubles_is_refused_past_its_limit() -> None:
    double = Expression("s ? s + s : 'x'")
    s: Any = None
    with pytest.raises(ExpressionError, match=r"'s \+ s' would be 2,097,152 characters, more "
                                              r"than the 1,048,576"):
        for _ in range(40):
            s = double.evaluate({"s": s})
    assert len(s) == MAX_TEXT


@pytest.mark.parametrize("source", ["\u0663 > 2", "\uff13 > 2", "x + \u0663"])  # ٣, fullwidth 3
def test_digits_are_ascii_as_in_behavior3s_runtimes(source: str) -> None:
    with pytest.raises(ExpressionError, match="unexpected character"):
        Expression(source)
