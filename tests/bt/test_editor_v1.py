"""behavior3editor 1.x tree files: the editor's and its runtimes' own samples, and files written
here for each rule (subtrees by path, ports, disabled nodes, vars and import, the name table)."""

from __future__ import annotations

import json
import logging
from pathlib import Path
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cyborg.app.cli import main
from cyborg.bt import (
    Action,
    Blackboard,
    ManualClock,
    NodeRegistry,
    Status,
    TreeLoadError,
    check_file,
    default_registry,
    load_tree,
    loads_tree,
)
from cyborg.bt.problems import Severity

SAMPLES = Path(__file__).resolve().parent / "data" / "behavior3_v1"
EDITOR = SAMPLES / "editor-sample"
SAMPLE_TREES = sorted(SAMPLES.rglob("*.json"))


class Greet(Action):
    """A node with ports, as a user writes one for v1 trees."""

    inputs = ("name", "greeting?")
    outputs = ("said",)

    def tick(self) -> Status:
        self.write("said", f"{self.read('greeting', 'Hello')}, {self.read('name')}")
        return Status.SUCCESS


def _registry() -> Any:
    registry = default_registry()
    registry.add(Greet)
    return registry


def _write(folder: Path, name: str, root: dict[str, Any], **top: Any) -> Path:
    path = folder / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps({"version": "1.8.2", "name": path.stem, "desc": "", **top,
                                "root": root}, indent=2), encoding="utf-8")
    return path


def _node(node_id: int, name: str, *children: dict[str, Any], **fields: Any) -> dict[str, Any]:
    node: dict[str, Any] = {"id": node_id, "name": name, **fields}
    if children:
        node["children"] = list(children)
    return node


def _errors(path: Path, **options: Any) -> list[Any]:
    return [p for p in check_file(path, **options) if p.is_error]


_EMPTY_CMPS = {"editor-sample/workdir/subtree2.json": ("editor-sample/workdir/subtree2.json", "2"),
               "editor-sample/workdir/monster.json": ("editor-sample/workdir/subtree2.json", "2"),
               "editor-sample/workdir/sub/subtree2.json": (
                   "editor-sample/workdir/sub/subtree2.json", "2")}
"""The one defect of the samples, by the file loaded: a Cmp with none of gt, ge, eq, lt, le
(behavior3editor's own check marks it too) in the editor's sample workdir, in its two
subtree2.json files, the first of them referenced by monster.json."""


def _defects(path: Path) -> list[tuple[str, str]]:
    """The sample defects a load of ``path`` meets: those of the files it reads."""
    defect = _EMPTY_CMPS.get(path.relative_to(SAMPLES).as_posix())
    return [defect] if defect else []


@pytest.mark.parametrize("path", SAMPLE_TREES, ids=lambda p: str(p.relative_to(SAMPLES)))
def test_every_sample_tree_loads_with_stubs_for_the_game_nodes(path: Path) -> None:
    """The editor's sample workdir, behavior3-ts's examples and behavior3lua's trees: only
    their game-specific nodes (Attack, GetHp, ...) and v1 stock nodes cyborg lacks need
    stubs; every subtree path resolves and every port binding fits. The sample's Cmp without
    a comparison is the only error; with a stub for Cmp every sample loads and ticks."""
    errors = _errors(path, stub_missing=Status.SUCCESS)
    assert [(Path(p.source).relative_to(SAMPLES).as_posix(), p.node_id)
            for p in errors] == _defects(path)
    registry = _registry_without("Cmp") if errors else default_registry()
    tree = load_tree(path, registry=registry, stub_missing=Status.SUCCESS, clock=ManualClock())
    assert tree.tick().status in Status


def _registry_without(name: str) -> NodeRegistry:
    registry = NodeRegistry()
    for node_type in default_registry().types():
        if node_type.name != name:
            registry.add(node_type.cls, node_type.name, origin=node_type.origin)
    return registry


def test_without_stubs_the_missing_nodes_are_named_with_file_line_and_id() -> None:
    monster = EDITOR / "workdir" / "monster.json"
    errors = _errors(monster, registry=_registry_without("Cmp"))
    by_node = {(Path(p.source).name, p.node_id): p for p in errors}
    get_hp = by_node[("monster.json", "3")]
    assert get_hp.line == 21 and get_hp.field == "name"
    assert "declared in node-config.b3-setting" in get_hp.message
    cmp_in_subtree = by_node[("subtree2.json", "2")]  # problems point into the subtree's file
    assert "unknown node name 'Cmp'" in cmp_in_subtree.message and cmp_in_subtree.line == 15
    assert "Cmp needs one of the args" in {(Path(p.source).name, p.node_id): p.message
                                           for p in _errors(monster)}[("subtree2.json", "2")], \
        "cyborg has Cmp now, and finds the sample's Cmp without a comparison"


def test_subtree_paths_resolve_against_the_workdir_and_each_reference_is_an_instance() -> None:
    tree = load_tree(EDITOR / "workdir" / "monster.json", registry=_registry_without("Cmp"),
                     stub_missing=Status.SUCCESS)  # a stub for the sample's Cmp without args
    structure = tree.structure.to_json()
    attack = structure["root"]["children"][0]["children"][0]  # the tree's Sequence "攻击"
    assert attack["label"] == "攻击"
    labels = [child["label"] for child in attack["children"]]
    assert labels == ["GetHp", "Cmp", "攻击", "subtree1"], "children in file order"
    get_hp = attack["children"][0]
    reference = get_hp["children"][0]
    assert (reference["category"], reference["label"], reference["tree_id"]) == (
        "tree", "subtree2", "workdir/subtree2")
    assert tree.by_uid["8/2"].name == "Log", "ids inside a reference are prefixed by its id"


def test_names_map_onto_cyborg_nodes_with_seconds_as_milliseconds(tmp_path: Path) -> None:
    path = _write(tmp_path, "mapped.json", _node(1, "Sequence", _node(
        2, "Selector", _node(3, "JustFailure"), _node(4, "Invert", _node(5, "JustFailure"))),
        _node(6, "Wait", args={"time": 1.5}), _node(7, "AlwaysSuccess", _node(8, "JustFailure"))))
    clock = ManualClock()
    tree = load_tree(path, clock=clock)
    assert [node.name for node in tree] == ["mapped", "MemSequence", "MemPriority", "Failer",
                                            "Inverter", "Failer", "Wait", "ForceSuccess",
                                            "Failer"]
    assert [node.label for node in tree][1:4] == ["Sequence", "Selector", "JustFailure"]
    assert tree.by_uid["6"].properties == {"milliseconds": 1500}
    assert tree.tick().status is Status.RUNNING
    clock.advance(1.4)
    assert tree.tick().status is Status.RUNNING
    clock.advance(0.2)
    assert tree.tick().status is Status.SUCCESS


def test_ports_bind_blackboard_keys_by_position(tmp_path: Path) -> None:
    path = _write(tmp_path, "greet.json", _node(1, "Sequence",
                  _node(2, "Greet", input=["visitor", ""], output=["last"]),
                  _node(3, "NotNull", input=["last"]), _node(4, "IsNull", input=["nobody"]),
                  _node(5, "Log", args={"message": "greeted"}, input=["last"])))
    blackboard = Blackboard({"visitor": "Ada"})
    tree = load_tree(path, registry=_registry(), blackboard=blackboard)
    assert tree.by_uid["2"].ports == {"name": "visitor", "said": "last"}
    assert tree.tick().status is Status.SUCCESS
    assert blackboard["last"] == "Hello, Ada"


def test_a_null_input_is_an_unbound_port_as_the_editor_reads_it(tmp_path: Path) -> None:
    """behavior3editor 1.x writes ``"input": [null]`` for a port left empty."""
    path = _write(tmp_path, "nulls.json", _node(1, "Sequence",
                  _node(2, "Greet", input=["visitor", None], output=["said"]),
                  _node(3, "Let", args={"value": 3}, input=[None], output=["hp"])))
    assert _errors(path, registry=_registry()) == []
    blackboard = Blackboard({"visitor": "Ada"})
    tree = load_tree(path, registry=_registry(), blackboard=blackboard)
    assert tree.by_uid["2"].ports == {"name": "visitor", "said": "said"}
    assert tree.tick().status is Status.SUCCESS
    assert (blackboard["said"], blackboard["hp"]) == ("Hello, Ada", 3)


def test_an_input_that_is_neither_a_name_nor_null_is_still_an_error(tmp_path: Path) -> None:
    path = _write(tmp_path, "bad.json", _node(1, "Let", args={"value": 3}, input=[7],
                                              output=["hp"]))
    (error,) = _errors(path)
    assert (error.node_id, error.field) == ("1", "input") and "null" in error.message


@pytest.mark.parametrize(("name", "time", "fragment"), [
    ("Wait", "abc", "arg 'time' must be a finite number of seconds, 0 or more, not 'abc'"),
    ("Wait", -2, "arg 'time' must be a finite number of seconds, 0 or more, not -2"),
    ("Wait", True, "arg 'time' must be a finite number of seconds, 0 or more, not True"),
    ("Timeout", [1], "arg 'time' must be a finite number of seconds, 0 or more, not [1]"),
    ("Timeout", None, "missing arg 'time' (seconds)"),
])
def test_a_bad_v1_time_is_named_as_the_file_names_it(tmp_path: Path, name: str, time: Any,
                                                     fragment: str) -> None:
    """The file says ``time`` in seconds; cyborg's node takes ``milliseconds``: an error must
    name the file's field and value, never the internal one."""
    args = {} if time is None else {"time": time}
    children = [_node(2, "JustSuccess")] if name == "Timeout" else []
    path = _write(tmp_path, "wait.json", _node(1, name, *children, args=args))
    (error,) = _errors(path)
    assert (error.node_id, error.field, error.line) == ("1", "time", 6)
    assert fragment in error.message and "milliseconds" not in error.message


def test_messages_about_a_renamed_v1_arg_name_it_as_the_file_does(tmp_path: Path) -> None:
    """A v1 Wait's ``time`` is cyborg's ``milliseconds``, behavior3lua's RepeatUntilSuccess's
    ``maxLoop`` cyborg's ``count``: a warning or error names the file's arg, never ours."""
    path = _write(tmp_path, "renamed.json", _node(1, "Sequence",
                  _node(2, "Wait", args={"time": 1, "random": 0.5}),
                  _node(3, "RepeatUntilSuccess", _node(4, "JustSuccess"), args={"maxLoop": "x"})))
    problems = {p.node_id: p for p in check_file(path) if p.field != "input"}
    wait, repeat = problems["2"], problems["3"]
    assert "unknown property 'random' is ignored (known: time)" in wait.message
    assert (repeat.field, repeat.is_error) == ("maxLoop", True)
    assert repeat.message.startswith("property 'maxLoop': expected")
    assert not any(word in p.message for p in problems.values()
                   for word in ("milliseconds", "'count'"))


def test_a_v1_time_written_as_text_is_read_as_seconds(tmp_path: Path) -> None:
    path = _write(tmp_path, "wait.json", _node(1, "Wait", args={"time": "1.5"}))
    assert load_tree(path).by_uid["1"].properties == {"milliseconds": 1500}


def test_a_cmp_without_a_comparison_is_found_by_validate_and_never_run(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """behavior3editor's own check refuses a Cmp with none of gt, ge, eq, lt, le; so does
    ``cyborg bt validate``, and ``bt run`` refuses to load it instead of raising per tick."""
    path = _write(tmp_path, "cmp.json", _node(1, "Sequence",
                  _node(2, "Let", args={"value": 3}, input=[""], output=["hp"]),
                  _node(3, "Cmp", input=["hp"])))
    (error,) = _errors(path)
    lines = path.read_text(encoding="utf-8").splitlines()
    assert (error.node_id, error.line) == ("3", lines.index('        "id": 3,') + 1)
    assert "Cmp needs one of the args gt, ge, eq, lt, le" in error.message
    assert main(["bt", "validate", str(path)]) == 1
    assert "invalid (1 error" in capsys.readouterr().out
    assert main(["bt", "run", str(path), "--fast", "--ticks", "2"]) == 1
    err = capsys.readouterr().err
    assert "Cmp needs one of the args" in err and "Traceback" not in err


def test_a_node_error_while_ticking_is_one_line_never_a_traceback(
        caplog: pytest.LogCaptureFixture, tmp_path: Path) -> None:
    """A stock v1 node that meets bad input reports it as the node's error, in one line."""
    path = _write(tmp_path, "cmp.json", _node(1, "Sequence",
                  _node(2, "Let", args={"value": "high"}, input=[""], output=["hp"]),
                  _node(3, "Cmp", args={"lt": 5}, input=["hp"])))
    tree = load_tree(path)
    with caplog.at_level(logging.DEBUG, logger="cyborg.bt"):
        assert tree.tick().status is Status.ERROR
    (record,) = [r for r in caplog.records if r.levelno >= logging.ERROR]
    assert record.exc_info is None
    assert "node 3 (Cmp, Cmp) returns ERROR in tick: Cmp compares a number, not 'high'" in (
        record.getMessage())


def test_a_required_port_left_unbound_and_extra_keys_are_reported(tmp_path: Path) -> None:
    path = _write(tmp_path, "unbound.json", _node(1, "Sequence",
                  _node(2, "Greet", input=["", "hi"], output=["said", "more"])))
    problems = check_file(path, registry=_registry())
    errors = [p for p in problems if p.is_error]
    assert [(p.node_id, p.field, p.line) for p in errors] == [("2", "input", 10)]
    assert "input port 'name' is not bound" in errors[0].message
    extra = [p for p in problems if p.severity is Severity.WARNING and p.field == "output"]
    assert len(extra) == 1 and "output #2 ('more') is ignored" in extra[0].message


def test_disabled_nodes_are_left_out_with_their_subtrees(tmp_path: Path) -> None:
    path = _write(tmp_path, "disabled.json", _node(1, "Sequence",
                  _node(2, "JustSuccess"),
                  _node(3, "Sequence", _node(4, "JustFailure"), disabled=True),
                  _node(5, "AlwaysFailure", _node(6, "JustFailure", disabled=True),
                        _node(7, "JustSuccess"))))
    tree = load_tree(path)
    assert [node.node_id for node in tree][1:] == ["1", "2", "5", "7"]
    assert tree.tick().status is Status.FAILURE


def test_subtree_paths_fall_back_to_the_files_folder_and_cycles_are_named(
        tmp_path: Path) -> None:
    _write(tmp_path, "parts/leaf.json", _node(1, "JustSuccess"))
    main_file = _write(tmp_path, "parts/main.json", _node(1, "Sequence",
                       _node(2, "Sequence", path="leaf.json"),
                       _node(3, "Sequence", path="leaf.json")))
    tree = load_tree(main_file)  # no workspace file: relative to the tree's own folder
    assert [node.uid for node in tree] == ["main", "1", "2", "2/1", "3", "3/1"]
    _write(tmp_path, "a.json", _node(1, "Sequence", _node(2, "Sequence", path="b.json")))
    b = _write(tmp_path, "b.json", _node(1, "Sequence", _node(2, "Sequence", path="a.json")))
    errors = _errors(b)
    assert any("cycle" in p.message and p.field == "name" for p in errors), errors


def test_a_missing_subtree_or_import_names_file_node_and_field(tmp_path: Path) -> None:
    path = _write(tmp_path, "broken.json", _node(1, "Sequence",
                  _node(2, "Sequence", path="trees/gone.json")), **{"import": ["vars/no.json"]})
    errors = _errors(path)
    fields = {(p.field, p.node_id) for p in errors}
    assert ("path", "2") in fields and ("import", None) in fields
    message = next(p for p in errors if p.field == "path").message
    assert "'trees/gone.json' was not found" in message
    with pytest.raises(TreeLoadError):
        load_tree(path)


def test_declared_vars_and_imports_check_every_binding(tmp_path: Path) -> None:
    _write(tmp_path, "vars/robot.json", _node(1, "JustSuccess"),
           vars=[{"name": "visitor", "desc": ""}])
    path = _write(tmp_path, "uses.json", _node(1, "Sequence",
                  _node(2, "Greet", input=["visitor"], output=["typo_said"])),
                  vars=[{"name": "said", "desc": ""}], **{"import": ["vars/robot.json"]})
    warnings = [p for p in check_file(path, registry=_registry()) if not p.is_error]
    assert [(p.node_id, p.field) for p in warnings] == [("2", "output")]
    assert "'typo_said' is not a declared variable" in warnings[0].message


def test_older_1x_files_with_integer_ids_and_declvar(tmp_path: Path) -> None:
    path = tmp_path / "old.json"
    path.write_text(json.dumps({"name": "old", "desc": "", "declvar": [{"name": "x"}],
                                "root": {"id": 1, "name": "IsNull", "input": ["y"]}}))
    warnings = [p for p in check_file(path) if not p.is_error]
    assert [(p.node_id, p.field) for p in warnings] == [("1", "input")]


def test_a_v1_stock_node_cyborg_lacks_is_explained_not_mistaken_for_ours(
        tmp_path: Path) -> None:
    path = _write(tmp_path, "delay.json", _node(1, "Delay", _node(2, "JustSuccess"),
                                                args={"delay": 1}))
    errors = _errors(path)
    assert len(errors) == 1 and "behavior3 v1's 'Delay' (schedules its child for later and " \
        "succeeds at once) has no equivalent" in errors[0].message, "not cyborg's Delay"
    assert _errors(path, stub_missing=Status.SUCCESS) == []


def test_v1_parallel_and_behavior3lua_names_map_onto_cyborgs_v1_nodes(tmp_path: Path) -> None:
    path = _write(tmp_path, "mapped_v1.json", _node(1, "Parallel",
                  _node(2, "RepeatUntilFailure", _node(3, "JustSuccess"), args={"maxLoop": 2}),
                  _node(4, "RetryUntilSuccess", _node(5, "JustFailure"), input=["tries"]),
                  _node(6, "Check", args={"value": "tries == 2"})))
    blackboard = Blackboard({"tries": 2})
    clock = ManualClock()
    tree = load_tree(path, blackboard=blackboard, clock=clock)
    assert [node.name for node in tree][1:] == ["ParallelAll", "RetryUntilFailure",
                                                "Succeeder", "RetryUntilSuccess", "Failer",
                                                "Check"]
    assert tree.by_uid["2"].properties == {"count": 2}
    assert tree.by_uid["4"].ports == {"count": "tries"}
    assert [tree.tick().status for _ in range(3)] == [Status.RUNNING] * 2 + [Status.SUCCESS]


def test_the_cli_takes_v1_files_and_node_definition_files(
        capsys: pytest.CaptureFixture[str], caplog: pytest.LogCaptureFixture) -> None:
    subtree = str(EDITOR / "workdir" / "subtree1.json")
    caplog.set_level(logging.INFO, "cyborg.bt.log")
    assert main(["bt", "validate", subtree]) == 0
    assert main(["bt", "run", subtree, "--fast", "--until-done"]) == 0
    out = capsys.readouterr().out
    assert "tick      1  RUNNING  subtree1 > 新建行为树 > Wait" in out
    assert "hello" in caplog.messages
    assert main(["bt", "dot", subtree]) == 0
    assert '"2" [label="Log", shape=box' in capsys.readouterr().out  # ids are the file's own
    assert main(["bt", "json", subtree]) == 0
    assert json.loads(capsys.readouterr().out)["root"]["tree_id"] == "workdir/subtree1"
    assert main(["bt", "validate", str(EDITOR / "node-config.b3-setting")]) == 0


def test_the_workdirs_node_definitions_fill_arg_defaults_and_shape_stubs(
        tmp_path: Path) -> None:
    (tmp_path / "robot.b3-workspace").write_text('{"files": [], "settings": {}}')
    (tmp_path / "node-config.b3-setting").write_text(json.dumps([
        {"name": "Log", "type": "Action", "desc": "log",
         "args": [{"name": "level", "type": "string?", "default": "warn"}]},
        {"name": "Scan", "type": "Condition", "desc": "look around", "input": ["area"],
         "output": ["found?"]}]))
    path = _write(tmp_path, "trees/patrol.json", _node(1, "Sequence",
                  _node(2, "Log", args={"message": "start"}),
                  _node(3, "Scan", input=["", "x"], output=["seen"])))
    problems = check_file(path, stub_missing=Status.RUNNING)
    assert [(p.node_id, p.field, p.is_error) for p in problems if "stub" not in p.message] == [
        ("3", "input", True), ("3", "input", False)], "ports checked against the definition"
    path = _write(tmp_path, "trees/patrol.json", _node(1, "Sequence",
                  _node(2, "Log", args={"message": "start"}), _node(3, "Scan", input=["x"])))
    tree = load_tree(path, stub_missing=Status.FAILURE)
    assert tree.by_uid["2"].properties == {"level": "warn", "message": "start"}
    assert tree.by_uid["3"].category.value == "condition"
    assert tree.tick().status is Status.FAILURE


def test_tree_files_saved_with_a_byte_order_mark_load(tmp_path: Path, shared: Path) -> None:
    exported = (shared / "trees" / "stock_nodes.tree.json").read_bytes()
    with_bom = tmp_path / "bom.tree.json"
    with_bom.write_bytes(b"\xef\xbb\xbf" + exported)
    assert len(load_tree(with_bom)) == len(load_tree(shared / "trees" / "stock_nodes.tree.json"))
    v1 = tmp_path / "bom_v1.json"
    v1.write_bytes(b"\xef\xbb\xbf" + json.dumps({"name": "t", "root": _node(1, "JustSuccess")})
                   .encode())
    assert load_tree(v1).tick().status is Status.SUCCESS


_json_values = st.recursive(
    st.none() | st.booleans() | st.integers(-3, 3) | st.floats(allow_nan=True)
    | st.sampled_from(["", "1", "Sequence", "Wait", "Log", "x", "sub.json"]),
    lambda inner: st.lists(inner, max_size=3) | st.dictionaries(
        st.sampled_from(["id", "name", "args", "input", "output", "children", "path",
                         "disabled", "desc", "time"]), inner, max_size=4),
    max_leaves=12)


@settings(max_examples=150, deadline=None)
@given(root=st.dictionaries(st.sampled_from(["id", "name", "args", "input", "output",
                                             "children", "path", "disabled"]),
                            _json_values, max_size=6),
       top=st.dictionaries(st.sampled_from(["vars", "declvar", "import", "version", "name"]),
                           _json_values, max_size=3))
def test_any_v1_shaped_input_loads_or_names_its_problems(root: dict[str, Any],
                                                         top: dict[str, Any]) -> None:
    text = json.dumps({**top, "root": root})
    try:
        tree = loads_tree(text, stub_missing=Status.SUCCESS)
    except TreeLoadError as exc:
        assert exc.problems and all(p.source == "<string>" for p in exc.problems)
    else:
        assert len(tree) >= 1


def test_a_tree_nested_too_deeply_is_a_located_error(tmp_path: Path) -> None:
    for levels in (300, 5000):  # deeper than cyborg builds; deeper than JSON reads
        text = "".join(f'{{"id": {depth}, "name": "Invert", "children": ['
                       for depth in range(levels))
        text += '{"id": "leaf", "name": "JustSuccess"}' + "]}" * levels
        path = tmp_path / f"deep{levels}.json"
        path.write_text(f'{{"name": "deep", "root": {text}}}')
        with pytest.raises(TreeLoadError) as caught:
            load_tree(path)
        assert "nested more deeply than" in str(caught.value), levels
        assert str(path) in str(caught.value)


def test_a_file_from_a_newer_editor_is_read_with_a_warning() -> None:
    monster = SAMPLES / "behavior3-ts-example" / "monster.json"  # "version": "2.0.0"
    (warning,) = [p for p in check_file(monster, stub_missing=Status.SUCCESS)
                  if p.field == "version"]
    assert warning.severity is Severity.WARNING and warning.line == 1
    assert "written by behavior3editor 2.0.0; read as a 1.x file" in warning.message
