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


# --- Older export forms: trees without "id", settings under "parameters" ---------------------
#
# Early behavior3editor exports (and behavior3py's tests/test_serialization.py fixture, which
# these tests mirror) have no tree "id", and nodes may carry "parameters", the older name of
# "properties". behavior3js loads both; so must we, with a warning that says what was assumed.

_SEQ = "50352f51-c3f3-4a95-bd9b-4721bcd7e315"
_LIMIT = "b2364dc1-d251-44c9-b3ba-80fc0c96aa55"
_OK = "ec40a510-f558-41a6-92ab-726be25715b4"
_MAX = "30c7361c-6d3a-4385-9b4d-6b8eedbd547a"
_RUN = "a01d941b-c248-4ef5-870d-cc58b913fe3d"
_ORPHAN = "8a1cff9f-9d1c-48db-ba7f-4543544506df"


def _b3_node(node_id: str, name: str, title: str, *, parameters: dict[str, Any] | None = None,
             properties: dict[str, Any] | None = None, **links: Any) -> dict[str, Any]:
    """A node in the fixture's key order, ``parameters`` before ``properties``."""
    return {"id": node_id, "name": name, "title": title, "description": "",
            "display": {"x": 0, "y": 0}, "parameters": parameters or {},
            "properties": properties or {}, **links}


def _b3py_export() -> dict[str, Any]:
    """A tree export shaped like behavior3py's test_serialization.py fixture.

    No ``id``, ``scope`` or ``version``; tree-level ``properties``; every node has a
    ``parameters`` key; decorators link with ``child``; one node is not connected; the
    ``custom_nodes`` come with the tree. The decorators' settings are *only* under
    ``parameters``: MemSequence[Limiter{maxLoop: 2}[Succeeder], MaxTime{maxTime: 100}[Runner]].
    """
    nodes = [
        _b3_node(_SEQ, "MemSequence", "Sequence2", properties={"b": "cv"},
                 children=[_LIMIT, _MAX]),
        _b3_node(_LIMIT, "Limiter", "Limit <maxLoop> Activations", parameters={"maxLoop": 2},
                 child=_OK),
        _b3_node(_OK, "Succeeder", "Succeeder"),
        _b3_node(_MAX, "MaxTime", "Max <maxTime>ms", parameters={"maxTime": 100}, child=_RUN),
        _b3_node(_RUN, "Runner", "Runner"),
        _b3_node(_ORPHAN, "Failer", "Failer"),
    ]
    return {"title": "Custom Name BT", "description": "description =)", "root": _SEQ,
            "display": {"camera_x": 492, "camera_y": 430.5, "camera_z": 1, "x": 0, "y": 0},
            "properties": {"a": 2},
            "nodes": {node["id"]: node for node in nodes},
            "custom_nodes": [{"name": "D", "title": "D", "category": "action"}]}


def _write_export(tmp_path: Path, data: Any, name: str = "custom_bt.json") -> tuple[Path, str]:
    path = tmp_path / name
    text = json.dumps(data, indent=4)
    path.write_text(text)
    return path, text


def _line_of(text: str, needle: str) -> int:
    return next(n for n, line in enumerate(text.splitlines(), 1) if needle in line)


def test_tree_without_id_takes_its_title_with_a_warning(tmp_path: Path) -> None:
    from cyborg.bt import Severity, read_project

    path, text = _write_export(tmp_path, _b3py_export())
    project = read_project(path)
    (tree,) = project.trees
    assert tree.id == "Custom Name BT"
    assert project.selected_tree == "Custom Name BT"
    (problem,) = [p for p in project.problems if p.field == "id"]
    assert problem.severity is Severity.WARNING
    assert (problem.source, problem.tree) == (str(path), "Custom Name BT")
    assert problem.line == _line_of(text, f'"{_SEQ}": {{')  # the tree's first node
    assert "'Custom Name BT'" in problem.message and "title" in problem.message
    # the single tree is the one that runs, and it runs under its derived id
    loaded = load_tree(path, registry=registry(), clock=ManualClock())
    assert loaded.tree_id == "Custom Name BT"


def test_untitled_tree_without_id_takes_the_file_stem(tmp_path: Path) -> None:
    from cyborg.bt import read_project

    data = _b3py_export()
    del data["title"]
    path, _ = _write_export(tmp_path, data, "patrol.json")
    project = read_project(path)
    assert [t.id for t in project.trees] == ["patrol"]
    assert project.selected_tree == "patrol"
    (problem,) = [p for p in project.problems if p.field == "id"]
    assert "'patrol'" in problem.message and "file name" in problem.message


def test_project_trees_without_id_get_unique_derived_ids(tmp_path: Path) -> None:
    from cyborg.bt import Severity, read_project

    def idless(title: str, script: str) -> dict[str, Any]:
        tree = tree_json(N("Scripted", script=script), title=title)
        del tree["id"]
        return tree

    # two untitled-id trees titled "Dock"; one titled like a later tree's id ("t2"); one
    # titled like a node name ("Succeeder"), which must not turn that node into a subtree
    trees = [idless("Dock", "S"), idless("Dock", "F"), idless("t2", "R"),
             idless("Succeeder", "E"), _simple_tree("t2", "Explicit")]
    text = project_json(trees, selected="t2")
    path = tmp_path / "project.b3.json"
    path.write_text(text)
    project = read_project(path)
    assert [t.id for t in project.trees] == ["Dock", "Dock (2)", "t2 (2)", "Succeeder (2)", "t2"]
    warnings = [p for p in project.problems if p.field == "id"]
    assert [p.severity for p in warnings] == [Severity.WARNING] * 4
    assert [p.tree for p in warnings] == ["Dock", "Dock", "t2", "Succeeder"]
    assert all(p.source == str(path) and p.line is not None for p in warnings)
    assert "'Dock (2)'" in warnings[1].message
    reg = registry()
    assert load_tree(path, registry=reg).tree_id == "t2"  # selectedTree still wins
    picked = load_tree(path, registry=reg, tree="Dock (2)")
    assert picked.tick().status is Status.FAILURE  # the second Dock, script "F"


def test_settings_under_parameters_drive_the_decorators(tmp_path: Path) -> None:
    path, _ = _write_export(tmp_path, _b3py_export())
    clock = ManualClock()
    tree = load_tree(path, registry=registry(), clock=clock)
    limiter, max_time = tree.by_uid[_LIMIT], tree.by_uid[_MAX]
    assert limiter.label == "Limit 2 Activations" and max_time.label == "Max 100ms"
    for _activation in range(2):  # maxLoop 2: two activations get through the Limiter
        assert tree.tick().status is Status.RUNNING  # Runner under MaxTime
        clock.advance(0.05)
        assert tree.tick().status is Status.RUNNING  # 50 ms < maxTime 100 ms
        clock.advance(0.06)
        assert tree.tick().status is Status.FAILURE  # 110 ms: MaxTime gives up
    third = tree.tick()
    assert third.status is Status.FAILURE
    assert (_LIMIT, Status.FAILURE) in third.visited  # the Limiter refused,
    assert _MAX not in dict(third.visited)  # so MaxTime was not reached


def test_parameters_warnings_name_file_line_node_and_field(tmp_path: Path) -> None:
    from cyborg.bt import Severity, check_file

    path, text = _write_export(tmp_path, _b3py_export())
    problems = check_file(path, registry=registry())
    assert not [p for p in problems if p.is_error]
    warned = {p.node_id: p for p in problems if p.field == "parameters"}
    assert set(warned) == {_LIMIT, _MAX}  # the empty "parameters" of the others are fine
    for node_id, key in ((_LIMIT, "maxLoop"), (_MAX, "maxTime")):
        problem = warned[node_id]
        assert problem.severity is Severity.WARNING
        assert (problem.source, problem.tree) == (str(path), "Custom Name BT")
        assert problem.line == _line_of(text, f'"{node_id}": {{')
        assert key in problem.message and "'properties'" in problem.message
    orphan = [p for p in problems if p.node_id == _ORPHAN]
    assert orphan and "not connected" in orphan[0].message


def test_properties_win_over_parameters_and_each_taken_key_is_reported() -> None:
    from tests.builders import Scripted

    data = tree_json(N("Scripted", id="s", tag="kept"))
    data["nodes"]["s"]["parameters"] = {"script": "F", "tag": "dropped"}
    text = json.dumps(data, indent=2)
    tree = loads_tree(text, registry=registry(), clock=ManualClock())
    assert tree.tick().status is Status.FAILURE  # "script" came from "parameters"
    node = tree.by_uid["s"]
    assert isinstance(node, Scripted) and node.tag == "kept"  # "properties" won
    warnings = [p for p in parse_project(text).problems if p.field == "parameters"]
    assert [p.node_id for p in warnings] == ["s", "s"]
    taken, ignored = warnings
    assert "'script'" in taken.message and "'tag'" not in taken.message
    assert "'tag'" in ignored.message and "'properties'" in ignored.message


def test_tree_level_parameters_fill_the_tree_properties() -> None:
    from cyborg.bt import Severity

    data = _simple_tree()
    data["properties"] = {"a": 2}
    data["parameters"] = {"a": 3, "z": 1}
    project = parse_project(json.dumps(data, indent=2))
    assert project.trees[0].properties == {"a": 2, "z": 1}
    warnings = [p for p in project.problems if p.field == "parameters"]
    assert {p.severity for p in warnings} == {Severity.WARNING}
    assert {p.node_id for p in warnings} == {None}
    assert {p.tree for p in warnings} == {"Simple"}
    assert any("'z'" in p.message for p in warnings)


@pytest.mark.parametrize("level", ["node", "tree"])
def test_parameters_that_is_not_an_object_is_an_error(level: str) -> None:
    from cyborg.bt import TreeLoadError

    data = _simple_tree()
    (data["nodes"]["a"] if level == "node" else data)["parameters"] = ["maxLoop", 2]
    with pytest.raises(TreeLoadError) as caught:
        parse_project(json.dumps(data, indent=2))
    (problem,) = [p for p in caught.value.problems if p.is_error]
    assert problem.field == "parameters" and "'parameters'" in problem.message
    assert problem.node_id == ("a" if level == "node" else None)
    assert problem.tree == "Simple" and problem.line is not None


def test_cli_validate_prints_older_form_warnings_and_exits_0(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from cyborg.app.cli import main

    path, text = _write_export(tmp_path, _b3py_export())
    assert main(["bt", "validate", str(path)]) == 0
    out = capsys.readouterr().out
    warnings = [line for line in out.splitlines() if ": warning: " in line]
    limit_line = _line_of(text, f'"{_LIMIT}": {{')
    assert any(line.startswith(f"{path}:{limit_line}: warning: ") and f"(id {_LIMIT})" in line
               and "parameters" in line for line in warnings)
    assert any("'id'" in line and "'Custom Name BT'" in line for line in warnings)
    assert f"{path}: ok (0 errors, " in out


def _repeater_tree(max_loop: str) -> str:
    """A 0.3.0 tree export: Repeater{maxLoop: ``max_loop``, as JSON text}[Succeeder]."""
    return """{"version": "0.3.0", "scope": "tree", "id": "t1", "title": "Forever",
 "root": "r", "properties": {},
 "nodes": {
  "r": {"id": "r", "name": "Repeater", "title": "Repeat <maxLoop>x",
        "properties": {"maxLoop": MAX_LOOP}, "child": "s"},
  "s": {"id": "s", "name": "Succeeder", "title": "Succeeder", "properties": {}}}}
""".replace("MAX_LOOP", max_loop)


@pytest.mark.parametrize("written", ["1e999", '"Infinity"', "1E+400"])
def test_a_repeater_looping_infinity_times_runs_forever_with_a_note(
        tmp_path: Path, written: str) -> None:
    """behavior3js loops ``while (maxLoop < 0 || i < maxLoop)``: a maxLoop of infinity (JSON
    writes it 1e999) never ends. It loads as -1 (forever), and a note says so."""
    from cyborg.bt import Severity, check_file

    path = tmp_path / "forever.b3.json"
    path.write_text(_repeater_tree(written), encoding="utf-8")
    (note,) = check_file(path, registry=registry())
    assert note.severity is Severity.NOTE and not note.is_error
    assert (note.node_id, note.field, note.line) == ("r", "maxLoop", 4)  # the node's line
    assert "infinity" in note.message and "forever" in note.message
    tree = load_tree(path, registry=registry(), clock=ManualClock())
    assert tree.by_uid["r"].max_loop == -1  # type: ignore[attr-defined]
    assert {tree.tick().status for _ in range(50)} == {Status.RUNNING}


def test_a_note_is_counted_apart_from_errors_and_warnings(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from cyborg.app.cli import main

    path = tmp_path / "forever.b3.json"
    path.write_text(_repeater_tree("1e999"), encoding="utf-8")
    assert main(["bt", "validate", str(path)]) == 0
    out = capsys.readouterr().out
    assert f"{path}:4: note: " in out
    assert f"{path}: ok (0 errors, 0 warnings, 1 note)" in out


@pytest.mark.parametrize("written", ["-1e999", '"-Infinity"', "NaN"])
def test_a_loop_count_of_minus_infinity_or_nan_is_still_an_error(written: str) -> None:
    from cyborg.bt import TreeLoadError

    with pytest.raises(TreeLoadError, match=r"'maxLoop'.*finite"):
        loads_tree(_repeater_tree(written), registry=registry(), clock=ManualClock())
