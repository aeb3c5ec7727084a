"""Every behavior3editor 0.3.0 export shape loads; unknown keys are ignored; order is kept."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from cyborg.bt import ManualClock, Status, load_tree, loads_tree, parse_project, render_title
from tests.builders import N, project_json, registry, tree_json


def _simple_tree(tree_id: str = "t1", title: str = "Simple") -> dict[str, Any]:
    return tree_json(N("MemSequence", N("Succeeder", id="a"), N("Wait", id="b", milliseconds=10),
                       id="seq"), tree_id=tree_id, title=title)


def test_project_export_runs_selected_tree() -> None:
    other = _simple_tree("t2", "Other")
    text = project_json([_simple_tree(), other], selected="t2")
    tree = loads_tree(text, registry=registry(), clock=ManualClock())
    assert tree.tree_id == "t2"
    assert tree.title == "Other"


def test_single_tree_export_with_its_own_custom_nodes() -> None:
    data = _simple_tree()
    data["custom_nodes"] = [{"version": "0.3.0", "scope": "node", "name": "Scripted",
                             "category": "action", "title": "Scripted", "description": None,
                             "properties": {}}]
    project = parse_project(json.dumps(data))
    assert project.kind == "tree"
    assert [d.name for d in project.definitions] == ["Scripted"]
    tree = loads_tree(json.dumps(data), registry=registry(), clock=ManualClock())
    assert tree.tick().status is Status.RUNNING


def test_desktop_project_wrapper_is_unwrapped(tmp_path: Path) -> None:
    wrapper = {"name": "My project", "description": "", "path": "/home/me/p.b3",
               "data": json.loads(project_json([_simple_tree()]))}
    path = tmp_path / "project.b3"
    path.write_text(json.dumps(wrapper))
    tree = load_tree(path, registry=registry(), clock=ManualClock())
    assert tree.title == "Simple"
    assert parse_project(path.read_text()).kind == "desktop"


def test_node_list_export_is_read_as_definitions() -> None:
    nodes = [{"version": "0.3.0", "scope": "node", "name": "Bedtime?", "category": "condition",
              "title": "Bedtime?", "description": None, "properties": {"hour": 22}},
             {"version": "0.3.0", "scope": "node", "name": "Led Dome Interpreter",
              "category": "action", "title": "Led Dome", "description": None, "properties": {}}]
    project = parse_project(json.dumps(nodes))
    assert project.kind == "nodes"
    assert [(d.name, d.category) for d in project.definitions] == [
        ("Bedtime?", "condition"), ("Led Dome Interpreter", "action")]
    assert project.trees == []


def test_unknown_keys_are_ignored() -> None:
    data = _simple_tree()
    data["category"] = "composite"
    data["parameters"] = {"x": 1}
    for node in data["nodes"].values():
        node["category"] = "composite"
        node["parameters"] = {}
        node["whatever"] = [1, 2]
    tree = loads_tree(json.dumps(data), registry=registry(), clock=ManualClock())
    assert len(tree) == 4


def test_children_keep_file_order() -> None:
    spec = N("Sequence", *(N("Scripted", id=f"c{i}", tag=str(i)) for i in (3, 1, 2)), id="s")
    data = tree_json(spec)
    tree = loads_tree(json.dumps(data), registry=registry(), clock=ManualClock())
    snapshot = tree.tick()
    assert [uid for uid, _ in snapshot.visited][:3] == ["c3", "c1", "c2"]
    assert [child.uid for child in tree.by_uid["s"].children] == ["c3", "c1", "c2"]


@pytest.mark.parametrize(("title", "properties", "expected"), [
    ("MoveTo <location>", {"location": "home"}, "MoveTo home"),
    ("Max <maxTime>ms", {"maxTime": 1000}, "Max 1000ms"),
    ("Repeat <maxLoop>x", {"maxLoop": -1}, "Repeat -1x"),
    ("MoveTo <location>", {}, "MoveTo <location>"),
    ("<a> and <b>", {"a": 1, "b": "two"}, "1 and two"),
    ("no placeholders", {"a": 1}, "no placeholders"),
])
def test_title_placeholders(title: str, properties: dict[str, Any], expected: str) -> None:
    assert render_title(title, properties) == expected


def test_label_rendered_and_raw_title_kept() -> None:
    spec = N("Wait", id="w", title="Wait <milliseconds>ms", milliseconds=2000)
    tree = loads_tree(json.dumps(tree_json(spec)), registry=registry(), clock=ManualClock())
    node = tree.by_uid["w"]
    assert node.title == "Wait <milliseconds>ms"
    assert node.label == "Wait 2000ms"
    structure = tree.structure.to_json()["root"]["children"][0]
    assert (structure["title"], structure["label"]) == ("Wait <milliseconds>ms", "Wait 2000ms")


def test_pick_tree_by_id_or_title() -> None:
    text = project_json([_simple_tree("t1", "First"), _simple_tree("t2", "Second")])
    reg = registry()
    assert loads_tree(text, registry=reg, tree="t2").title == "Second"
    assert loads_tree(text, registry=reg, tree="Second").tree_id == "t2"
    assert loads_tree(text, registry=reg).tree_id == "t1"


def test_without_selected_tree_the_unreferenced_tree_is_root() -> None:
    inner = _simple_tree("inner", "Inner")
    outer = tree_json(N("Sequence", N("inner", id="ref"), id="top"), tree_id="outer",
                      title="Outer")
    data = json.loads(project_json([inner, outer]))
    data["selectedTree"] = None
    tree = loads_tree(json.dumps(data), registry=registry())
    assert tree.tree_id == "outer"
