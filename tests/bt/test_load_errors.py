"""Bad input gives a clear error naming file and line, tree, node id/title and field.

Each case here is a bad input the loader handles; nothing half-built is returned.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from cyborg.bt import (
    Action,
    Problem,
    Status,
    TreeLoadError,
    Wait,
    check_file,
    load_tree,
    loads_tree,
)
from tests.builders import N, project_json, registry, tree_json


def _errors(text: str, **options: Any) -> list[Problem]:
    with pytest.raises(TreeLoadError) as caught:
        loads_tree(text, registry=registry(), **options)
    return [p for p in caught.value.problems if p.is_error]


def _file(tmp_path: Path, data: Any, name: str = "tree.json") -> Path:
    path = tmp_path / name
    path.write_text(data if isinstance(data, str) else json.dumps(data, indent=2))
    return path


def test_malformed_json_names_line_and_column(tmp_path: Path) -> None:
    path = _file(tmp_path, '{\n  "trees": [\n    {"id": "a",,}\n  ]\n}\n')
    with pytest.raises(TreeLoadError) as caught:
        load_tree(path)
    (problem,) = caught.value.problems
    assert (problem.source, problem.line, problem.column) == (str(path), 3, 16)
    assert str(problem).startswith(f"{path}:3:16: error: malformed JSON")


def test_unreadable_file() -> None:
    with pytest.raises(TreeLoadError, match=r"missing\.json: error: cannot read the file"):
        load_tree("missing.json")


def test_unknown_node_name_names_node_tree_and_registered_names(tmp_path: Path) -> None:
    data = tree_json(N("Sequence", N("Bedtime?", id="bed", title="Is it bedtime?"), id="s"),
                     title="Evening")
    path = _file(tmp_path, data)
    with pytest.raises(TreeLoadError) as caught:
        load_tree(path, registry=registry())
    (problem,) = caught.value.problems
    assert problem.node_id == "bed"
    assert problem.node_title == "Is it bedtime?"
    assert problem.tree == "Evening"
    assert problem.field == "name"
    assert problem.line == _line_of(path, '"bed": {')
    text = str(problem)
    assert "unknown node name 'Bedtime?'" in text
    assert "registered: " in text and "MemSequence" in text and "Scripted" in text


def _line_of(path: Path, needle: str) -> int:
    for number, line in enumerate(path.read_text().splitlines(), start=1):
        if needle in line:
            return number
    raise AssertionError(f"{needle} not in {path}")


@pytest.mark.parametrize(("spec", "field", "words"), [
    (N("Wait", id="x", milliseconds="soon"), "milliseconds", "expected float, got 'soon'"),
    (N("Repeater", N("Succeeder"), id="x", maxLoop=1.5), "maxLoop", "expected int, got 1.5"),
    (N("Repeater", N("Succeeder"), id="x", maxLoop=True), "maxLoop", "expected int, got True"),
    (N("MaxTime", N("Succeeder"), id="x"), "maxTime", "missing property 'maxTime'"),
    (N("Timeout", N("Succeeder"), id="x"), "milliseconds", "missing property 'milliseconds'"),
    (N("Limiter", N("Succeeder"), id="x", maxLoop=1, max_loop=2), "max_loop", "repeats"),
])
def test_wrong_or_missing_property(spec: N, field: str, words: str) -> None:
    (problem,) = _errors(json.dumps(tree_json(spec)))
    assert problem.node_id == "x"
    assert problem.field == field
    assert words in problem.message


@pytest.mark.parametrize(("spec", "words"), [
    (N("MaxTime", N("Succeeder"), id="x", maxTime=0), "maxTime must be more than 0 ms"),
    (N("Repeater", N("Succeeder"), id="x", maxLoop=0), "maxLoop must be -1 (forever)"),
    (N("Retry", N("Succeeder"), id="x", maxAttempts=-3), "maxAttempts must be -1"),
    (N("Limiter", N("Succeeder"), id="x", maxLoop=-1), "maxLoop must be 0 or more"),
    (N("Wait", id="x", milliseconds=-5), "milliseconds must be 0 or more"),
    (N("Parallel", N("Succeeder"), id="x", successThreshold=2),
     "successThreshold must be -1 (all) or 1..1"),
])
def test_out_of_range_property(spec: N, words: str) -> None:
    (problem,) = _errors(json.dumps(tree_json(spec)))
    assert problem.node_id == "x"
    assert words in problem.message


def test_unknown_property_is_a_warning_not_an_error() -> None:
    spec = N("MemPriority", N("Succeeder"), id="x", mode="-")
    tree = loads_tree(json.dumps(tree_json(spec)), registry=registry())
    assert tree.tick().status is Status.SUCCESS


def test_numbers_typed_as_text_are_converted() -> None:
    tree = loads_tree(json.dumps(tree_json(N("Wait", id="w", milliseconds="250"))),
                      registry=registry())
    wait = tree.by_uid["w"]
    assert isinstance(wait, Wait) and wait.milliseconds == 250.0


def test_decorator_without_child() -> None:
    (problem,) = _errors(json.dumps(tree_json(N("Inverter", id="inv", title="Not"))))
    assert problem.node_id == "inv" and problem.node_title == "Not"
    assert "decorator has no child" in problem.message


def test_leaf_with_children() -> None:
    data = tree_json(N("Sequence", N("Succeeder", id="leaf"), id="s"))
    data["nodes"]["leaf"]["children"] = ["s2"]
    data["nodes"]["s2"] = {"id": "s2", "name": "Failer", "title": "Failer", "properties": {}}
    (problem,) = _errors(json.dumps(data))
    assert problem.node_id == "leaf"
    assert "action nodes cannot have children" in problem.message


def test_dangling_child_id() -> None:
    data = tree_json(N("Sequence", N("Succeeder", id="ok"), id="s"))
    data["nodes"]["s"]["children"].append("ghost")
    (problem,) = _errors(json.dumps(data))
    assert (problem.node_id, problem.field) == ("s", "children")
    assert "child 'ghost' is not a node of this tree" in problem.message


def test_dangling_decorator_child() -> None:
    data = tree_json(N("Inverter", N("Succeeder", id="ok"), id="inv"))
    data["nodes"]["inv"]["child"] = "ghost"
    problems = _errors(json.dumps(data))
    assert any("child 'ghost' is not a node" in p.message and p.node_id == "inv"
               for p in problems)


def test_missing_root() -> None:
    data = tree_json(N("Succeeder", id="a"), title="Empty")
    data["root"] = None
    (problem,) = _errors(json.dumps(data))
    assert problem.tree == "Empty" and problem.field == "root"
    assert "nothing is connected to its Root block" in problem.message


def test_root_not_a_node() -> None:
    data = tree_json(N("Succeeder", id="a"))
    data["root"] = "nope"
    (problem,) = _errors(json.dumps(data))
    assert "root 'nope' is not a node of this tree" in problem.message


def test_node_with_two_parents_and_loops() -> None:
    data = tree_json(N("Sequence", N("Sequence", id="inner"), N("Succeeder", id="leaf"), id="s"))
    data["nodes"]["inner"]["children"] = ["leaf", "s"]
    messages = [p.message for p in _errors(json.dumps(data))]
    assert any("is also an ancestor" in m for m in messages)
    assert any("already has another parent" in m for m in messages)


def test_key_and_id_mismatch_and_missing_name() -> None:
    data = tree_json(N("Sequence", N("Succeeder", id="a"), id="s"))
    data["nodes"]["a"]["id"] = "b"
    del data["nodes"]["s"]["name"]
    problems = _errors(json.dumps(data))
    assert {(p.node_id, p.field) for p in problems} == {("a", "id"), ("s", "name")}


def test_constructor_that_raises_is_reported_with_its_node() -> None:
    class Picky(Action):
        def __init__(self, level: int = 1) -> None:
            if level > 3:
                raise ValueError("level must be at most 3")

        def tick(self) -> Status:
            return Status.SUCCESS

    reg = registry()
    reg.add(Picky)
    with pytest.raises(TreeLoadError) as caught:
        loads_tree(json.dumps(tree_json(N("Picky", id="p", level=9), reg=reg)), registry=reg)
    (problem,) = caught.value.problems
    assert problem.node_id == "p"
    assert "Picky(level=9) raised ValueError: level must be at most 3" in problem.message


@pytest.mark.parametrize(("data", "words"), [
    ({"hello": 1}, "not a behavior3editor export"),
    ("[1, 2]", "custom node #1 has no 'name'"),
    ('"text"', "expected a JSON object or array"),
    ({"root": {"id": 1, "children": []}}, "node has no 'name'"),  # behavior3 v1
    ({"root": {"id": 1, "name": "Log", "args": []}}, "'args' must be an object"),
    ({"version": "0.3.0", "scope": "project", "trees": {}}, "'trees' must be an array"),
    ({"scope": "tree", "id": "t", "root": "a", "nodes": []}, "'nodes' must be an object"),
])
def test_not_an_export(data: Any, words: str) -> None:
    text = data if isinstance(data, str) else json.dumps(data)
    problems = _errors(text)
    assert any(words in p.message for p in problems), problems


def test_selected_tree_missing_and_ambiguous_titles() -> None:
    a = tree_json(N("Succeeder"), tree_id="a", title="Same")
    b = tree_json(N("Succeeder"), tree_id="b", title="Same")
    (problem,) = _errors(project_json([a, b], selected="zzz"))
    assert "selectedTree 'zzz' is not in the file" in problem.message
    (problem,) = _errors(project_json([a, b]), tree="Same")
    assert "several trees are titled 'Same'" in problem.message
    (problem,) = _errors(project_json([a, b]), tree="Other")
    assert "no tree has the id or title 'Other'" in problem.message


def test_check_file_reports_all_problems_in_all_trees(tmp_path: Path) -> None:
    good = tree_json(N("Sequence", N("Nope", id="n1"), N("Inverter", id="i1"), id="s1"),
                     tree_id="good", title="Main")
    unused = tree_json(N("Wait", id="w2", milliseconds="x"), tree_id="unused", title="Unused")
    path = _file(tmp_path, project_json([good, unused], selected="good"))
    problems = check_file(path, registry=registry())
    found = {(p.tree, p.node_id, p.severity.value) for p in problems}
    assert found == {("Main", "n1", "error"), ("Main", "i1", "error"),
                     ("Unused", "w2", "error")}
    assert all(p.source == str(path) and p.line is not None for p in problems)


def test_orphan_nodes_are_warnings() -> None:
    data = tree_json(N("Succeeder", id="a"))
    data["nodes"]["lonely"] = {"id": "lonely", "name": "Failer", "title": "Failer",
                               "properties": {}}
    tree = loads_tree(json.dumps(data), registry=registry())
    assert "lonely" not in tree.by_uid


def test_decorator_with_two_children() -> None:
    data = tree_json(N("Sequence", N("Succeeder", id="a"), N("Failer", id="b"), id="s"))
    data["nodes"]["s"]["name"] = "Inverter"
    (problem,) = _errors(json.dumps(data))
    assert problem.node_id == "s"
    assert "a decorator takes exactly one child, it has 2" in problem.message


def test_composite_exported_with_child_key_is_accepted() -> None:
    data = tree_json(N("Inverter", N("Succeeder", id="a"), id="s"))
    data["nodes"]["s"]["name"] = "Sequence"
    tree = loads_tree(json.dumps(data), registry=registry())
    assert [child.uid for child in tree.by_uid["s"].children] == ["a"]


def test_both_child_and_children() -> None:
    data = tree_json(N("Sequence", N("Succeeder", id="a"), id="s"))
    data["nodes"]["s"]["child"] = "a"
    (problem,) = _errors(json.dumps(data))
    assert (problem.node_id, problem.field) == ("s", "child")
    assert "both 'child' and 'children'" in problem.message
