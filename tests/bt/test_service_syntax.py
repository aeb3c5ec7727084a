"""The ``services`` declaration's grammar: what it reads, and where it points at mistakes."""

from __future__ import annotations

from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cyborg.bt.service_syntax import ServiceSyntaxError, parse_services


def test_names_options_and_literals() -> None:
    calls = parse_services(' BatteryWatch(interval=1.0, key=battery); ClosestGoal ;'
                           ' Say(text="a, b; \\"c\\"", times=-2, loud=TRUE, ratio=.5e1,'
                           " path=/robot1/goals, quiet=false,)")
    assert [call.name for call in calls] == ["BatteryWatch", "ClosestGoal", "Say"]
    assert calls[0].options == {"interval": 1.0, "key": "battery"}
    assert calls[1].options == {} and calls[1].text == "ClosestGoal"
    say = calls[2].options
    assert say == {"text": 'a, b; "c"', "times": -2, "loud": True, "ratio": 5.0,
                   "path": "/robot1/goals", "quiet": False}
    assert isinstance(say["times"], int) and isinstance(say["ratio"], float)
    assert calls[0].column == 2 and calls[1].column == 43
    assert calls[0].option_columns == {"interval": 15, "key": 29}
    assert calls[0].text == "BatteryWatch(interval=1.0, key=battery)"


@pytest.mark.parametrize("text", ["", "   ", ";", " ; ;"])
def test_blank_text_declares_nothing(text: str) -> None:
    assert parse_services(text) == []


@pytest.mark.parametrize(("text", "column", "words"), [
    ("9Watch", 1, "expected a service name"),
    ("Watch(", 7, "not closed"),
    ("Watch(interval 1)", 16, "expected '=' after option 'interval'"),
    ("Watch(interval=)", 16, "has no value"),
    ("Watch(key=two words)", 11, "'two words' is not a value"),
    ("Watch(key=1x)", 11, "'1x' is not a value"),
    ("Watch(key='open)", 11, "quoted text is not closed"),
    ("Watch(key='a\\q')", 13, "unknown escape"),
    ("Watch(a=1 b=2)", 9, "'1 b=2' is not a value for option 'a'"),
    ("Watch(a='x' b=2)", 13, "expected ',' or ')' after the value of 'a'"),
    ("Watch(a=1, a=2)", 12, "option 'a' is given twice (first at column 7)"),
    ("Watch; Other; Watch(a=1)", 15, "'Watch' is declared twice"),
    ("Watch Other", 7, "expected ';' between two services"),
    ("Watch(=1)", 7, "expected an option name"),
    ("Watch()x", 8, "expected ';'"),
])
def test_errors_name_the_column(text: str, column: int, words: str) -> None:
    with pytest.raises(ServiceSyntaxError) as caught:
        parse_services(text)
    assert caught.value.column == column
    assert words in caught.value.message
    assert str(caught.value).startswith(f"column {column}: ")


names = st.from_regex(r"[A-Za-z_][A-Za-z0-9_]{0,8}", fullmatch=True)
words = names.filter(lambda word: word.lower() not in ("true", "false"))
values = st.one_of(st.integers(-10**6, 10**6),
                   st.floats(allow_nan=False, allow_infinity=False, width=32),
                   st.booleans(), words, st.text(max_size=12))


def _literal(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int | float):
        return repr(float(value)) if isinstance(value, float) else str(value)
    escaped = value.replace("\\", "\\\\").replace('"', '\\"')
    return f'"{escaped}"'


@settings(max_examples=300, deadline=None)
@given(st.dictionaries(names, st.dictionaries(names, values, max_size=4), max_size=4))
def test_any_written_declaration_reads_back(declared: dict[str, dict[str, Any]]) -> None:
    text = "; ".join(name + ("(" + ", ".join(f"{key}={_literal(value)}"
                                               for key, value in options.items()) + ")"
                             if options else "")
                     for name, options in declared.items())
    calls = parse_services(text)
    assert {call.name: call.options for call in calls} == declared


@settings(max_examples=500, deadline=None)
@given(st.text(alphabet=st.sampled_from("Ab_1 ,;()='\"\\.-/eE+\n\t"), max_size=40)
       | st.text(max_size=30))
def test_any_text_parses_or_fails_with_a_column_inside_it(text: str) -> None:
    try:
        parse_services(text)
    except ServiceSyntaxError as exc:
        assert 1 <= exc.column <= len(text) + 1
