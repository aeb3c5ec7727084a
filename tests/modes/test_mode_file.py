"""Reading mode files: a good one resolves; every bad one names file, line, mode or transition."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from cyborg.bt import Problem
from cyborg.modes import ModeFileError, parse_mode_file, read_mode_file
from tests.modes.machines import write_modes, write_project

GOOD = """\
project = "mission.b3.json"
initial = "normal"
min_dwell = 2.0

[modes.normal]
tree = "patrol"

[modes.low_battery]
tree = "charge"
min_dwell = 5

[modes.demo]
tree = "demo"
max_time = 60.0
then = "normal"

[[transitions]]
from = "normal"
to = "low_battery"
when = "battery.percent < 20"

[[transitions]]
from = "low_battery"
to = "normal"
when = "battery.percent >= 95"

[[transitions]]
from = "normal"
to = "demo"
on_request = true
guard = "!docked"
"""
TREES = {"patrol": "R", "charge": "R", "demo": "R", "spare": "S"}


def problems(folder: Path, text: str) -> list[Problem]:
    write_project(folder, TREES)
    with pytest.raises(ModeFileError) as caught:
        read_mode_file(write_modes(folder, text))
    found = caught.value.problems
    assert found and all(p.is_error for p in found)
    assert all(p.source == str(folder / "mission.modes.toml") for p in found
               if "mission.b3.json" not in p.source)
    return found


def only(folder: Path, text: str) -> Problem:
    found = problems(folder, text)
    assert len(found) == 1, [str(p) for p in found]
    return found[0]


def line_of(text: str, fragment: str, occurrence: int = 1) -> int:
    lines = [n for n, line in enumerate(text.splitlines(), 1) if fragment in line]
    return lines[occurrence - 1]


def test_a_good_file_resolves_every_name(tmp_path: Path) -> None:
    write_project(tmp_path, TREES)
    spec = read_mode_file(write_modes(tmp_path, GOOD))
    assert spec.initial == "normal"
    assert list(spec.modes) == ["normal", "low_battery", "demo"]
    assert spec.modes["normal"].min_dwell == 2.0 and spec.modes["low_battery"].min_dwell == 5.0
    assert (spec.modes["demo"].max_time, spec.modes["demo"].then) == (60.0, "normal")
    assert spec.modes["demo"].line == line_of(GOOD, "[modes.demo]")
    first, second, third = spec.transitions
    assert second.sources == ("low_battery",) and second.target == "normal"
    assert first.label == "transition 1 (normal → low_battery)"
    assert first.when is not None and first.when.source == "battery.percent < 20"
    assert third.on_request and third.guard is not None and third.line == line_of(
        GOOD, "[[transitions]]", 3)


def test_trees_are_found_by_title_and_in_several_files_of_either_generation(
        tmp_path: Path) -> None:
    write_project(tmp_path, {"Patrol the rooms": "R"}, name="patrol.b3.json")
    (tmp_path / "charge.json").write_text(json.dumps({
        "version": "1.8.2", "name": "charge",
        "root": {"id": "1", "name": "Scripted", "args": {"script": "R"}}}))
    text = """files = ["patrol.b3.json", "charge.json"]
initial = "normal"
[modes.normal]
tree = "Patrol the rooms"
[modes.low]
tree = "charge"
[[transitions]]
from = "*"
to = "low"
event = "battery_low"
[[transitions]]
from = "low"
to = "normal"
event = "charged"
"""
    spec = read_mode_file(write_modes(tmp_path, text))
    assert spec.modes["normal"].project.source.endswith("patrol.b3.json")
    assert spec.modes["low"].project.kind == "v1"


def test_toml_syntax_errors_and_repeated_modes_give_their_line(tmp_path: Path) -> None:
    problem = only(tmp_path, GOOD + "\n[modes.demo]\ntree = \"demo\"\n")
    assert problem.line == len(GOOD.splitlines()) + 2
    assert "not valid TOML" in problem.message and "demo" in problem.message
    problem = only(tmp_path, 'initial = "normal\n')
    assert problem.line == 1 and problem.column is not None


@pytest.mark.parametrize(("value", "said"), [
    ("[" * 1000 + "]" * 1000, "nested more than 32 deep"),
    ("{a=" * 1000 + "1" + "}" * 1000, "nested more than 32 deep"),
    ("1" + "0" * 5000, "a number of more than 100 digits"),
])
def test_what_tomllib_cannot_read_is_a_located_problem(tmp_path: Path, value: str,
                                                       said: str) -> None:
    """1,000 nested arrays or inline tables raised RecursionError from tomllib, a 5,001-digit
    number ValueError, and a 401-digit min_dwell OverflowError: each is one located problem."""
    text = GOOD + f"\nx = {value}\n"
    problem = only(tmp_path, text)
    assert said in problem.message and problem.line == len(GOOD.splitlines()) + 2
    dwell = only(tmp_path, GOOD.replace("[modes.normal]", "min_dwell = 1" + "0" * 400
                                        + "\n[modes.normal]", 1))
    assert "more than 100 digits" in dwell.message and dwell.line is not None
    quoted = GOOD + '\nnote = "' + "[" * 1000 + '"\n'  # brackets in a string are text
    assert "nested" not in only(tmp_path, quoted).message


def test_an_unknown_tree_lists_the_trees_there_are(tmp_path: Path) -> None:
    text = GOOD.replace('tree = "charge"', 'tree = "charging"')
    problem = only(tmp_path, text)
    assert problem.line == line_of(text, 'tree = "charging"')
    assert "mode 'low_battery'" in problem.message and "'charging'" in problem.message
    assert "'patrol' (id patrol) in mission.b3.json" in problem.message
    assert problem.field == "tree"


@pytest.mark.parametrize(("old", "new", "words"), [
    ('initial = "normal"', 'initial = "norml"', ["'initial'", "'norml'", "did you mean 'normal'"]),
    ('to = "low_battery"', 'to = "low_batery"',
     ["transition 1 (normal → low_batery) leads nowhere", "did you mean 'low_battery'"]),
    ('from = "low_battery"', 'from = "lowbattery"',
     ["transition 2 (lowbattery → normal)", "'from'", "did you mean 'low_battery'"]),
    ('then = "normal"', 'then = "nromal"', ["mode 'demo'", "'then'", "'nromal'"]),
])
def test_unknown_modes_are_named_with_the_closest_one(tmp_path: Path, old: str, new: str,
                                                        words: list[str]) -> None:
    text = GOOD.replace(old, new)
    found = problems(tmp_path, text)
    problem = found[0]
    assert problem.line == line_of(text, new), str(problem)
    for word in words:
        assert word in problem.message, problem.message


def test_a_transition_without_to_leads_nowhere(tmp_path: Path) -> None:
    text = GOOD.replace('to = "demo"\n', "")
    problem = only(tmp_path, text)
    assert "transition 3 (normal → ?) leads nowhere" in problem.message
    assert problem.line == line_of(text, "[[transitions]]", 3)


def test_a_bad_expression_gives_its_column_in_the_file(tmp_path: Path) -> None:
    text = GOOD.replace('"battery.percent < 20"', '"battery.percent < "')
    problem = only(tmp_path, text)
    assert problem.line == line_of(text, "battery.percent < \"")
    assert "transition 1 (normal → low_battery): 'when' does not parse" in problem.message
    # "at the end" of the expression: the column of its closing quote in the file
    assert problem.column == text.splitlines()[problem.line - 1].rindex('"') + 1
    text = GOOD.replace('"!docked"', '"docked = 1"')
    problem = only(tmp_path, text)
    assert "'guard'" in problem.message and "compare with '=='" in problem.message


def test_an_unreachable_mode_is_an_error(tmp_path: Path) -> None:
    text = GOOD + '\n[modes.lost]\ntree = "spare"\n'
    problem = only(tmp_path, text)
    assert "mode 'lost' cannot be reached from the initial mode 'normal'" in problem.message
    assert problem.line == line_of(text, "[modes.lost]")


def test_then_and_requests_make_modes_reachable(tmp_path: Path) -> None:
    write_project(tmp_path, TREES)
    text = GOOD + ('\n[modes.extra]\ntree = "spare"\n[[transitions]]\nfrom = "demo"\n'
                   'to = "extra"\non_request = true\n')
    assert "extra" in read_mode_file(write_modes(tmp_path, text)).reachable()


def test_repeated_transitions_and_self_loops_are_errors(tmp_path: Path) -> None:
    text = GOOD + '\n[[transitions]]\nfrom = "normal"\nto = "low_battery"\n' \
                  'when = "battery.percent < 20"\n'
    problem = only(tmp_path, text)
    assert "transition 4 (normal → low_battery) repeats transition 1" in problem.message
    assert problem.line == line_of(text, "[[transitions]]", 4)
    text = GOOD + '\n[[transitions]]\nfrom = "demo"\nto = "demo"\nevent = "again"\n'
    assert "leads back to the mode it leaves" in only(tmp_path, text).message


@pytest.mark.parametrize(("old", "new", "words"), [
    ("min_dwell = 2.0", 'min_dwell = "2"', ["the file: 'min_dwell' is a number of seconds"]),
    ("max_time = 60.0", "max_time = 0", ["mode 'demo': 'max_time'", "more than 0"]),
    ("min_dwell = 5", "min_dwell = -1", ["mode 'low_battery': 'min_dwell'"]),
    ("on_request = true", 'on_request = "yes"', ["transition 3", "'on_request' must be true"]),
    ('from = "normal"\nto = "demo"', 'from = 3\nto = "demo"', ["transition 3", "'from'"]),
    ('tree = "patrol"', "tree = 7", ["mode 'normal': 'tree' must name"]),
    ('[modes.demo]', '[modes."demo mode"]', ["mode 'demo mode': a mode's name"]),
])
def test_wrong_types_name_the_key(tmp_path: Path, old: str, new: str, words: list[str]) -> None:
    text = GOOD.replace(old, new, 1)
    found = problems(tmp_path, text)
    problem = next(p for p in found if words[0] in p.message)
    assert problem.line == line_of(text, new.splitlines()[0]), str(problem)
    for word in words:
        assert word in problem.message


@pytest.mark.parametrize(("old", "new", "words", "key"), [
    ('tree = "patrol"', 'tre = "patrol"', ["mode 'normal': unknown key 'tre'",
                                           "did you mean 'tree'"], 'tre = "patrol"'),
    ('when = "battery.percent < 20"', 'wen = "battery.percent < 20"',
     ["transition 1 (normal → low_battery): unknown key 'wen'", "did you mean 'when'"],
     "wen ="),
    ('initial = "normal"', 'initial = "normal"\nintial = "x"',
     ["the file: unknown key 'intial'", "did you mean 'initial'"], "intial ="),
])
def test_unknown_keys_suggest_the_closest(tmp_path: Path, old: str, new: str,
                                          words: list[str], key: str) -> None:
    text = GOOD.replace(old, new)
    found = problems(tmp_path, text)
    problem = next(p for p in found if "unknown key" in p.message)
    assert problem.line == line_of(text, key)
    for word in words:
        assert word in problem.message


def test_triggers_are_exactly_one(tmp_path: Path) -> None:
    text = GOOD.replace("on_request = true\n", "")
    problem = only(tmp_path, text)
    assert "transition 3 (normal → demo) has no trigger" in problem.message
    text = GOOD.replace("on_request = true", 'on_request = true\nevent = "go"')
    assert "has 2 triggers (event, on_request)" in only(tmp_path, text).message


def test_every_problem_is_reported_at_once(tmp_path: Path) -> None:
    text = (GOOD.replace('tree = "charge"', 'tree = "nope"')
            .replace('"!docked"', '"!"').replace('initial = "normal"', 'initial = "x"'))
    found = problems(tmp_path, text)
    messages = "\n".join(p.message for p in found)
    assert "'nope'" in messages and "'guard' does not parse" in messages
    assert "'initial' names the mode 'x'" in messages
    assert len({p.line for p in found}) == 3
    assert str(found[0]).startswith(f"{tmp_path / 'mission.modes.toml'}:")


def test_the_tree_files_are_checked(tmp_path: Path) -> None:
    write_project(tmp_path, TREES)
    text = GOOD.replace("mission.b3.json", "missing.b3.json")
    with pytest.raises(ModeFileError) as caught:
        read_mode_file(write_modes(tmp_path, text))
    assert any("missing.b3.json" in p.source and "cannot read" in p.message
               for p in caught.value.problems)
    both = 'files = ["a.json"]\n' + GOOD
    assert any("either 'project'" in p.message for p in problems(tmp_path, both))
    assert "names no trees" in only(tmp_path, GOOD.replace(
        'project = "mission.b3.json"\n', "")).message


def test_a_file_that_cannot_be_read_names_itself(tmp_path: Path) -> None:
    with pytest.raises(ModeFileError) as caught:
        read_mode_file(tmp_path)
    assert caught.value.problems[0].source == str(tmp_path)
    assert "not a regular file" in str(caught.value)


def test_a_lone_surrogate_in_the_text_is_located() -> None:
    with pytest.raises(ModeFileError) as caught:
        parse_mode_file('project = "a\ud800.json"\n', "odd.modes.toml")
    problem = caught.value.problems[0]
    assert (problem.line, problem.column) == (1, 13) and "U+D800" in problem.message
    str(caught.value).encode("utf-8")


def test_a_file_name_with_a_nul_character_is_refused(tmp_path: Path) -> None:
    text = GOOD.replace('"mission.b3.json"', '"mission\\u0000.json"')
    problem = only(tmp_path, text)
    assert "'project' must be a file name" in problem.message and problem.line == 1
