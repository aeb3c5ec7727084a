"""What the monitor makes of a runner's mode state (cyborg.monitor.mode_source): a machine
that cannot be drawn whole is named line by line, never dropped silently; the runner's own
problems come first; whatever JSON arrives, the result is a drawable machine or problems, and
what goes to the pages is bounded."""

from __future__ import annotations

import json
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cyborg.bus.msgs.builtin_interfaces.msg import Time
from cyborg.bus.msgs.cyborg_msgs.msg import ModeState
from cyborg.monitor.mode_source import TEXT_LIMIT, machine_of, view_of


def _state(machine: str, problems: list[str] | None = None, mode: str = "a") -> ModeState:
    return ModeState(entered=Time(sec=2, nanosec=500_000_000), mode=mode, held=False,
                     transitions=3, machine=machine, problems=problems or [])


GOOD = {"schema": "cyborg.modes.machine/1", "initial": "a",
        "modes": [{"name": "a", "title": "A"}, {"name": "b", "title": "B"}],
        "transitions": [{"number": 1, "from": ["a"], "to": "b", "trigger": "event",
                         "event": "go"}]}


@pytest.mark.parametrize(("machine", "drawn", "problem"), [
    ("{not json", False, "not JSON"),
    (json.dumps({**GOOD, "schema": "other/2"}), False, "schema is 'other/2'"),
    (json.dumps({**GOOD, "modes": []}), False, "no modes"),
    (json.dumps({**GOOD, "modes": "ab"}), False, "no modes"),
    (json.dumps({**GOOD, "modes": [{"name": "a"}, {"name": "a"}, {"title": "x"}]}), True,
     "mode 2 has no name"),
    (json.dumps({**GOOD, "transitions": [{"number": 4, "from": ["a"], "to": "nowhere"}]}),
     True, "transition 4: to 'nowhere' is no mode"),
    (json.dumps({**GOOD, "transitions": [{"number": 5, "from": ["zz"], "to": "b"}]}),
     True, "transition 5: from"),
    (json.dumps({**GOOD, "transitions": [7]}), True, "transition 1 is not an object"),
    (json.dumps({**GOOD, "transitions": [{"from": [["a"]], "to": "b"}]}), True,
     "transition 1: from"),
    (json.dumps({**GOOD, "transitions": [{"number": True, "from": ["a"], "to": ["b"]}]}),
     True, """transition 1: to '["b"]' is no mode"""),
    (json.dumps({**GOOD, "initial": ["a"]}), True, "initial mode"),
    (json.dumps({**GOOD, "initial": "q"}), True, "initial mode 'q'"),
    (json.dumps({**GOOD, "modes": [{"name": "a", "then": "gone"}]}), True, "then 'gone'"),
])
def test_a_machine_that_cannot_be_drawn_whole_is_named_never_blank(
        machine: str, drawn: bool, problem: str) -> None:
    view = view_of(_state(machine))
    assert (view.machine is not None) is drawn
    assert any(problem in line for line in view.problems), view.problems


def test_the_runners_problems_come_first_and_a_sound_machine_has_none() -> None:
    view = view_of(_state(json.dumps(GOOD), ["m.toml:3: error: mode 'b': no tree"]))
    assert view.problems == ("m.toml:3: error: mode 'b': no tree",)
    assert view.entered == 2.5 and view.count == 3 and view.mode_names() == ["a", "b"]
    assert machine_of(json.dumps(GOOD))[1] == []
    unknown = view_of(_state(json.dumps(GOOD), mode="zz"))
    assert unknown.problems == ("the current mode 'zz' is no mode of the machine",)


JSON = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats(allow_nan=False)
    | st.text(max_size=300) | st.sampled_from(["a", "b", "*", "cyborg.modes.machine/1"]),
    lambda inner: st.lists(inner, max_size=6) | st.dictionaries(
        st.sampled_from(["schema", "initial", "modes", "transitions", "name", "title", "from",
                         "to", "then", "max_time", "trigger", "when", "number", "x"]),
        inner, max_size=8),
    max_leaves=40)


@settings(max_examples=300, deadline=None)
@given(JSON, st.booleans())
def test_any_json_is_a_drawable_machine_or_named_problems(data: Any, schema: bool) -> None:
    if schema and isinstance(data, dict):
        data = {**data, "schema": "cyborg.modes.machine/1"}
    view = view_of(_state(json.dumps(data)))
    assert view.machine is not None or view.problems, "never blank without a reason"
    if view.machine is not None:
        names = view.mode_names()
        assert names and len(set(names)) == len(names)
        for transition in view.machine["transitions"]:
            assert transition["to"] in names
            assert all(source == "*" or source in names for source in transition["from"])
        for mode in view.machine["modes"]:
            assert mode["then"] is None or mode["then"] in names
            assert all(len(value) <= TEXT_LIMIT for value in mode.values()
                       if isinstance(value, str))
    json.dumps(view.wire(), allow_nan=False)  # strict JSON for the pages
