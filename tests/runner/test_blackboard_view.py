"""The monitor's view of the blackboard is strict JSON of bounded size whatever nodes wrote:
a list that holds itself and a 5,000-digit integer broke get_blackboard, and the monitor's
blackboard went stale."""

from __future__ import annotations

from typing import Any

from hypothesis import given, settings
from hypothesis import strategies as st

from cyborg.runner.blackboard_view import (
    MAX_CHARACTERS,
    MAX_DEPTH,
    MAX_ITEMS,
    MAX_TEXT,
    blackboard_json,
)
from tests.strict_json import strict_loads


def shown(scopes: dict[str, Any]) -> Any:
    text = blackboard_json(scopes)
    assert len(text) <= MAX_CHARACTERS + 2 * MAX_TEXT + 1000
    return strict_loads(text)


def test_a_list_that_holds_itself_is_shown_up_to_where_it_loops() -> None:
    looped: list[Any] = [1]
    looped.append(looped)
    board: dict[str, Any] = {"l": looped}
    board["me"] = board
    assert shown({"global": board}) == {"global": {
        "l": [1, "(not shown: it holds itself)"], "me": "(not shown: it holds itself)"}}


def test_numbers_past_a_double_or_json_are_shown_as_javascript_would_or_said() -> None:
    view = shown({"tree": {"big": 10 ** 5000, "large": 2 ** 60, "inf": float("inf"),
                           "nan": float("nan"), "small": 7}})["tree"]
    assert view["big"] == "(not shown: an integer of about 5,000 digits)"
    assert view["large"] == float(2 ** 60) and view["small"] == 7
    assert (view["inf"], view["nan"]) == ("inf", "nan")


def test_long_texts_long_lists_and_deep_nesting_are_cut_and_counted() -> None:
    deep: Any = "bottom"
    for _ in range(100):
        deep = [deep]
    view = shown({"g": {"text": "x" * (3 * MAX_TEXT), "list": list(range(5000)),
                        "deep": deep, "thing": object()}})["g"]
    assert view["text"].endswith(f"… ({3 * MAX_TEXT:,} characters)")
    assert len(view["list"]) == MAX_ITEMS + 1
    assert view["list"][-1] == f"(not shown: {5000 - MAX_ITEMS:,} more items)"
    level, levels = view["deep"], 0
    while isinstance(level, list):
        level, levels = level[0], levels + 1
    assert level == f"(not shown: nested deeper than {MAX_DEPTH})" and levels < MAX_DEPTH
    assert view["thing"].startswith("<object object")


def test_a_huge_blackboard_is_cut_at_its_size() -> None:
    board = {f"k{index}": "y" * MAX_TEXT for index in range(500)}  # 5 M characters
    view = shown({"global": board})["global"]
    assert 50 < len(view) < 500
    assert view["(not shown)"] == (f"{501 - len(view):,} more entries: the blackboard is past "
                                   f"{MAX_CHARACTERS:,} characters")


VALUES = st.recursive(
    st.one_of(st.none(), st.booleans(), st.integers(-10**400, 10**400), st.floats(),
              st.text(max_size=20)),
    lambda inner: st.one_of(st.lists(inner, max_size=5),
                            st.dictionaries(st.one_of(st.text(max_size=5), st.integers()),
                                            inner, max_size=5)),
    max_leaves=30)


@settings(max_examples=200, deadline=None)
@given(value=VALUES, loop=st.booleans())
def test_any_blackboard_is_strict_json(value: Any, loop: bool) -> None:
    if loop and isinstance(value, list):
        value.append(value)
    if loop and isinstance(value, dict):
        value["self"] = value
    shown({"global": {"v": value}})
