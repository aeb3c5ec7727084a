"""Hostile tree files: each attack of issue 19 (items 8 and 10) is refused with a located error
or works, and never raises another exception, hangs or exhausts the stack.

Every hostile file is built in ``tmp_path`` (or as text) and every case is bounded: caps that
need big inputs are tested with the cap lowered, the one default-cap explosion (2^20 instances)
must stop within seconds, and anything that could block runs on a thread given a time limit.

The last part is a hypothesis fuzz suite over tree files of both formats (150 examples each,
about 5 s in all): every input loads, and then ticks, halts, draws and serialises, or raises
TreeLoadError whose problems are all located; never another exception, never a hang.
"""

from __future__ import annotations

import itertools
import json
import math
import os
import sys
import tempfile
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from cyborg.bt import (
    Action,
    Blackboard,
    Condition,
    Inverter,
    ManualClock,
    Problem,
    Status,
    Succeeder,
    Tree,
    TreeLoadError,
    check_file,
    default_registry,
    load_tree,
    loads_tree,
)
from cyborg.bt import limits as bt_limits
from cyborg.bt.dot import structure_to_dot
from cyborg.bt.node import TickRecord
from cyborg.bt.registry import NodeRegistry

# ---------------------------------------------------------------------------- helpers


class Below(Condition):
    """A condition with a property that explicitly allows infinity (its default is inf)."""

    def __init__(self, below: float = math.inf, radius: float = 0.5, count: int = 0) -> None:
        self.below, self.radius, self.count = below, radius, count

    def tick(self) -> Status:
        return Status.SUCCESS


class Deep(Action):
    """Records how deep the stack is when it ticks; raises when asked."""

    frames = 0

    def __init__(self, fail: bool = False) -> None:
        self.fail = fail

    def tick(self) -> Status:
        frame: Any = sys._getframe()
        count = 0
        while frame is not None:
            count, frame = count + 1, frame.f_back
        Deep.frames = max(Deep.frames, count)
        if self.fail:
            raise RuntimeError("deep failure")
        return Status.SUCCESS


def _registry() -> NodeRegistry:
    registry = default_registry(entry_points=False)
    registry.add(Below)
    registry.add(Deep)
    return registry


def _tree(tree_id: str, nodes: dict[str, Any], root: str) -> dict[str, Any]:
    return {"id": tree_id, "title": tree_id, "description": "", "root": root,
            "properties": {}, "nodes": nodes}


def _chain(levels: int, name: str = "Inverter", leaf: str = "Succeeder",
           leaf_props: dict[str, Any] | None = None) -> dict[str, Any]:
    """``levels`` nodes named ``name``, each the parent of the next, over one leaf."""
    nodes: dict[str, Any] = {}
    link = "child" if name == "Inverter" else "children"
    for level in range(levels):
        target = f"n{level + 1}"
        nodes[f"n{level}"] = {"id": f"n{level}", "name": name,
                              link: target if link == "child" else [target]}
    nodes[f"n{levels}"] = {"id": f"n{levels}", "name": leaf, "properties": leaf_props or {}}
    return {"scope": "tree", **_tree("main", nodes, "n0")}


def _one(name: str, properties: dict[str, Any], title: str = "") -> str:
    node = {"id": "x", "name": name, "title": title or name, "properties": properties}
    return json.dumps({"scope": "tree", **_tree("main", {"x": node}, "x")})


def _errors(call: Callable[[], object]) -> list[Problem]:
    with pytest.raises(TreeLoadError) as caught:
        call()
    errors = [p for p in caught.value.problems if p.is_error]
    assert errors
    for problem in caught.value.problems:
        assert_located(problem)
    return errors


def assert_located(problem: Problem) -> None:
    """A problem names its file and where in it: a line, a node id or a field."""
    assert problem.source, problem
    assert problem.line is not None or problem.node_id is not None \
        or problem.field is not None, problem
    str(problem).encode("utf-8")  # printable, whatever the file held


def _bounded(call: Callable[[], object], seconds: float = 10.0) -> object:
    """Run ``call`` on a daemon thread; fail (instead of hanging) if it takes too long."""
    outcome: list[object] = []

    def run() -> None:
        try:
            outcome.append(call())
        except BaseException as exc:  # handed back to the test
            outcome.append(exc)

    thread = threading.Thread(target=run, daemon=True)
    thread.start()
    thread.join(seconds)
    assert not thread.is_alive(), f"still running after {seconds} s"
    if isinstance(outcome[0], BaseException):
        raise outcome[0]
    return outcome[0]


def _v1(root: dict[str, Any], **top: Any) -> str:
    return json.dumps({"name": "t", "root": root, **top})


# ---------------------------------------------------------------------------- nesting
def test_a_tree_nested_995_levels_is_a_located_error_naming_the_cap() -> None:
    errors = _errors(lambda: loads_tree(json.dumps(_chain(995, "Sequence"))))
    (error,) = [e for e in errors if "nested more deeply than" in e.message]
    assert f"{bt_limits.MAX_DEPTH} levels" in error.message and "max_depth" in error.message
    assert error.node_id is not None and error.field == "children"


def test_989_chained_decorators_are_a_located_error() -> None:
    errors = _errors(lambda: loads_tree(json.dumps(_chain(989))))
    assert any("nested more deeply than" in e.message for e in errors)


def test_a_v1_file_nested_995_levels_is_a_located_error(tmp_path: Path) -> None:
    text = "".join(f'{{"id": {level}, "name": "Invert", "children": [' for level in range(995))
    text += '{"id": "leaf", "name": "JustSuccess"}' + "]}" * 995
    path = tmp_path / "deep.json"
    path.write_text(f'{{"name": "deep", "root": {text}}}')
    errors = _errors(lambda: load_tree(path))
    assert any("nested more deeply than" in e.message for e in errors)


def test_decorator_chains_below_the_recursion_limit_are_refused_at_load() -> None:
    """490-988 chained decorators used to validate "ok" and then fail every tick."""
    for levels in (490, 700, 988):
        text = json.dumps(_chain(levels))
        errors = _errors(lambda: loads_tree(text))  # noqa: B023 (called at once)
        assert any(f"nested more deeply than {bt_limits.MAX_DEPTH}" in e.message
                   for e in errors)


def _stack_depth() -> int:
    frame: Any = sys._getframe(1)
    count = 0
    while frame is not None:
        count, frame = count + 1, frame.f_back
    return count


def test_a_tree_at_the_depth_cap_loads_and_ticks_with_every_node_timed(
        caplog: pytest.LogCaptureFixture) -> None:
    """The cap leaves room: the deepest tree accepted ticks with hooks wrapping every node,
    from a stack already 300 frames deep, and a leaf that raises is logged, not a crash."""
    # depth counts the root tree's own node: 1 + (MAX_DEPTH - 2) decorators + the leaf
    text = json.dumps(_chain(bt_limits.MAX_DEPTH - 2, leaf="Deep", leaf_props={"fail": True}))
    tree = loads_tree(text, registry=_registry())
    tree.hooks.timing = True

    def tick_from(depth: int) -> Status:
        return tick_from(depth - 1) if depth else tree.tick().status

    assert tick_from(300 - _stack_depth()) is Status.ERROR
    (deep,) = [node for node in tree.nodes if node.name == "Deep"]
    assert isinstance(deep.last_error, RuntimeError)
    assert "deep failure" in caplog.text
    assert Deep.frames < sys.getrecursionlimit() - 50
    with pytest.raises(TreeLoadError):
        loads_tree(json.dumps(_chain(bt_limits.MAX_DEPTH - 1)), registry=_registry())


def test_max_depth_can_be_lowered_and_raised_with_the_recursion_limit(tmp_path: Path) -> None:
    path = tmp_path / "chain.json"
    path.write_text(json.dumps(_chain(20)))
    assert load_tree(path, max_depth=22) is not None
    errors = _errors(lambda: load_tree(path, max_depth=21))
    assert any("nested more deeply than 21 levels" in e.message for e in errors)
    assert any("nested more deeply than 21" in p.message
               for p in check_file(path, max_depth=21))
    with pytest.raises(ValueError, match="setrecursionlimit"):
        load_tree(path, max_depth=100_000)


def test_2000_chained_subtree_references_are_a_located_error() -> None:
    trees = [_tree(f"t{i}", {"r": {"id": "r", "name": f"t{i + 1}"}}, "r") for i in range(2000)]
    trees.append(_tree("t2000", {"r": {"id": "r", "name": "Succeeder"}}, "r"))
    text = json.dumps({"trees": trees, "selectedTree": "t0"})
    errors = _errors(lambda: _bounded(lambda: loads_tree(text)))
    assert any("nested more deeply than" in e.message and e.node_id == "r" for e in errors)


def test_2000_chained_v1_subtree_files_are_a_located_error(tmp_path: Path) -> None:
    for index in range(2000):
        root = {"id": 1, "name": "Sequence", "path": f"t{index + 1}.json"}
        (tmp_path / f"t{index}.json").write_text(_v1(root))
    (tmp_path / "t2000.json").write_text(_v1({"id": 1, "name": "JustSuccess"}))
    errors = _errors(lambda: _bounded(lambda: load_tree(tmp_path / "t0.json")))
    assert any("nested more deeply than" in e.message for e in errors)


def test_2000_chained_v1_imports_do_not_exhaust_the_stack(tmp_path: Path) -> None:
    for index in range(2000):
        (tmp_path / f"v{index}.json").write_text(json.dumps(
            {"vars": [{"name": f"x{index}"}], "import": [f"v{index + 1}.json"]}))
    (tmp_path / "v2000.json").write_text(json.dumps({"vars": [{"name": "last"}]}))
    root = {"id": 1, "name": "JustSuccess", "output": ["last"]}
    (tmp_path / "main.json").write_text(_v1(root, **{"import": ["v0.json"]}))
    tree = _bounded(lambda: load_tree(tmp_path / "main.json"))
    assert isinstance(tree, Tree)


# ---------------------------------------------------------------------------- node count
def _doubling(levels: int) -> str:
    """``levels`` trees, each referencing the next twice: 2^levels instances of the last."""
    trees = []
    for i in range(levels):
        nodes = {"s": {"id": "s", "name": "Sequence", "children": ["a", "b"]},
                 "a": {"id": "a", "name": f"t{i + 1}"}, "b": {"id": "b", "name": f"t{i + 1}"}}
        trees.append(_tree(f"t{i}", nodes, "s"))
    trees.append(_tree(f"t{levels}", {"r": {"id": "r", "name": "Succeeder"}}, "r"))
    return json.dumps({"trees": trees, "selectedTree": "t0"})


def test_20_levels_of_doubled_references_stop_at_the_node_cap() -> None:
    started = time.monotonic()
    errors = _errors(lambda: _bounded(lambda: loads_tree(_doubling(20)), 30))
    assert time.monotonic() - started < 30
    (error,) = [e for e in errors if "node instances" in e.message]
    assert f"{bt_limits.MAX_NODES:,}" in error.message and "max_nodes" in error.message


def test_max_nodes_is_a_parameter(tmp_path: Path) -> None:
    text = _doubling(6)
    count = len(loads_tree(text))
    assert count == 2 ** 8 - 2  # each tree: its own node, a Sequence, two copies of the next
    assert loads_tree(text, max_nodes=count) is not None
    errors = _errors(lambda: loads_tree(text, max_nodes=count - 1))
    assert any(f"more than {count - 1} node instances" in e.message for e in errors)
    path = tmp_path / "doubling.json"
    path.write_text(text)
    assert any("node instances" in p.message for p in check_file(path, max_nodes=100))


def test_checking_many_trees_that_share_a_big_subtree_builds_it_once(tmp_path: Path) -> None:
    """check_file checks every tree; it used to expand the shared subtree once per tree (30
    trees of 65,534 instances each: 87 s). Now each tree is built once."""
    project = json.loads(_doubling(14))
    project["trees"] += [_tree(f"top{i}", {"r": {"id": "r", "name": "t0"}}, "r")
                         for i in range(30)]
    project["trees"].append(_tree("deep", {"r": {"id": "r", "name": "t0"}}, "r"))
    project["trees"][-1]["nodes"] = _chain(bt_limits.MAX_DEPTH - 16)["nodes"]
    project["trees"][-1]["nodes"][f"n{bt_limits.MAX_DEPTH - 16}"]["name"] = "t0"
    project["trees"][-1]["root"] = "n0"
    path = tmp_path / "shared.json"
    path.write_text(json.dumps(project))
    started = time.monotonic()
    problems = _bounded(lambda: check_file(path), 60)
    assert isinstance(problems, list)
    assert time.monotonic() - started < 30
    # the tree that nests the shared subtree too deeply is still found, at its reference
    (deep,) = [p for p in problems if "nested more deeply" in p.message]
    assert deep.tree == "deep" and deep.node_id == f"n{bt_limits.MAX_DEPTH - 16}"
    assert len(problems) == 1, problems


def test_doubled_v1_subtree_files_stop_at_the_node_cap(tmp_path: Path) -> None:
    for index in range(20):
        child = {"id": 2, "name": "Sequence", "path": f"d{index + 1}.json"}
        root = {"id": 1, "name": "Sequence", "children": [child, {**child, "id": 3}]}
        (tmp_path / f"d{index}.json").write_text(_v1(root))
    (tmp_path / "d20.json").write_text(_v1({"id": 1, "name": "JustSuccess"}))
    errors = _errors(lambda: _bounded(lambda: load_tree(tmp_path / "d0.json", max_nodes=5000)))
    assert any("more than 5,000 node instances" in e.message for e in errors)


# ---------------------------------------------------------------------------- files
@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs here")
def test_a_fifo_is_refused_at_once(tmp_path: Path) -> None:
    fifo = tmp_path / "tree.json"
    os.mkfifo(fifo)
    errors = _errors(lambda: _bounded(lambda: load_tree(fifo), 5))
    assert "not a regular file" in errors[0].message
    assert [p.message for p in check_file(fifo)] == [errors[0].message]


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs here")
def test_v1_files_that_are_fifos_are_refused_at_once(tmp_path: Path) -> None:
    os.mkfifo(tmp_path / "sub.json")
    os.mkfifo(tmp_path / "vars.json")
    os.mkfifo(tmp_path / "node-config.b3-setting")
    root = {"id": 1, "name": "Sequence", "children": [
        {"id": 2, "name": "Sequence", "path": "sub.json"}, {"id": 3, "name": "JustSuccess"}]}
    (tmp_path / "main.json").write_text(_v1(root, **{"import": ["vars.json"]}))
    with pytest.raises(TreeLoadError) as caught:
        _bounded(lambda: load_tree(tmp_path / "main.json"), 5)
    reasons = [p.message for p in caught.value.problems]
    assert sum("not a regular file" in reason for reason in reasons) == 3, reasons


def test_a_folder_is_refused(tmp_path: Path) -> None:
    errors = _errors(lambda: load_tree(tmp_path))
    assert "not a regular file (a folder)" in errors[0].message


def test_a_file_over_the_size_cap_is_refused_before_it_is_read(tmp_path: Path) -> None:
    path = tmp_path / "huge.json"
    with path.open("wb") as sparse:
        sparse.truncate(bt_limits.MAX_FILE_BYTES + 1)
    (error,) = _errors(lambda: load_tree(path))
    assert "16 MiB" in error.message and "max_bytes" in error.message
    small = tmp_path / "small.json"
    small.write_text(json.dumps(_chain(3)) + " " * 2000)
    (error,) = _errors(lambda: load_tree(small, max_bytes=1000))
    assert "1,000 bytes" in error.message
    assert load_tree(small, max_bytes=4000) is not None
    (error,) = _errors(lambda: loads_tree(json.dumps(_chain(3)), max_bytes=10))
    assert "max_bytes" in error.message


def test_the_size_cap_counts_the_files_a_v1_tree_references(tmp_path: Path) -> None:
    (tmp_path / "sub.json").write_text(_v1({"id": 1, "name": "JustSuccess"}) + " " * 3000)
    (tmp_path / "main.json").write_text(_v1({"id": 1, "name": "Sequence", "path": "sub.json"}))
    assert load_tree(tmp_path / "main.json") is not None
    errors = _errors(lambda: load_tree(tmp_path / "main.json", max_bytes=2000))
    assert any("max_bytes" in e.message for e in errors)


def test_a_subtree_file_used_many_times_is_read_once(tmp_path: Path) -> None:
    (tmp_path / "sub.json").write_text(_v1({"id": 1, "name": "JustSuccess"}) + " " * 1000)
    uses = [{"id": i, "name": "Sequence", "path": "sub.json"} for i in range(2, 52)]
    main = tmp_path / "main.json"
    main.write_text(_v1({"id": 1, "name": "Sequence", "children": uses}))
    budget = main.stat().st_size + (tmp_path / "sub.json").stat().st_size
    assert len(load_tree(main, max_bytes=budget)) == 1 + 1 + 50 * 2


def test_caps_can_be_raised_from_the_environment(tmp_path: Path,
                                                 monkeypatch: pytest.MonkeyPatch) -> None:
    path = tmp_path / "doubling.json"
    path.write_text(_doubling(6))
    monkeypatch.setenv("CYBORG_TREE_MAX_NODES", "100")
    errors = _errors(lambda: load_tree(path))
    assert any("CYBORG_TREE_MAX_NODES" in e.message for e in errors)
    assert load_tree(path, max_nodes=1000) is not None  # a parameter wins
    monkeypatch.setenv("CYBORG_TREE_MAX_NODES", "lots")
    (error,) = _errors(lambda: load_tree(path))
    assert error.field == "CYBORG_TREE_MAX_NODES" and "whole number" in error.message


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


# ---------------------------------------------------------------------------- walking trees
def _programmatic_chain(levels: int) -> Tree:
    record, blackboard = TickRecord(), Blackboard()
    leaf: Any = Succeeder()
    nodes = [leaf]
    for _ in range(levels):
        parent = Inverter()
        nodes.append(parent)
    for index, node in enumerate(nodes):
        node.bind(uid=f"n{index}", node_id=f"n{index}", name=type(node).__name__,
                  title="", label="", description="", properties={}, tree_uid="",
                  subtree_depth=0, blackboard=blackboard, record=record)
    for child, parent in itertools.pairwise(nodes):
        parent.adopt([child])
    return Tree(nodes[-1], record=record, blackboard=blackboard, clock=ManualClock())


def test_walking_describing_and_drawing_a_deep_tree_do_not_recurse() -> None:
    tree = _programmatic_chain(5000)  # built in Python, past any file's cap
    assert len(tree) == 5001 and tree.nodes[-1].name == "Succeeder"
    structure = tree.structure.to_json()
    depth, entry = 0, structure["root"]
    while entry["children"]:
        depth, entry = depth + 1, entry["children"][0]
    assert depth == 5000
    dot = structure_to_dot(structure, collapsed=["n4000"])
    assert "(+4000)" in dot


def test_dot_output_is_unchanged_by_the_iterative_walk() -> None:
    text = _doubling(2)
    tree = loads_tree(text)
    assert tree.to_dot() == _recursive_dot_reference(tree.structure.to_json())


def _recursive_dot_reference(structure: dict[str, Any]) -> str:
    """The order in which the former recursive exporter wrote lines, for comparison."""
    from cyborg.bt.dot import _FILL, _IDLE, _SHAPES, quote

    lines = [f"digraph {quote(structure.get('title') or 'behaviour tree')} {{",
             '  graph [rankdir=TB, ordering=out, fontname="Helvetica"];',
             '  node [fontname="Helvetica", fontsize=11];', '  edge [arrowsize=0.6];']
    cluster = [0]

    def emit(node: dict[str, Any], indent: str) -> None:
        children = node.get("children", [])
        attributes = _SHAPES.get(node["category"], "shape=box")
        lines.append(f"{indent}{quote(node['id'])} [label={quote(node['label'] or node['name'])}"
                     f", {attributes}, fillcolor={quote(_FILL.get('', _IDLE))}];")
        for child in children:
            subtree = child["category"] == "tree" and child.get("children")
            if subtree or len(children) > 1:
                cluster[0] += 1
                frame = (f'label={quote(child["label"])}; style=dashed; color="#9aa0a6"; '
                         "peripheries=1;" if subtree else 'label=""; peripheries=0;')
                lines.extend([f"{indent}subgraph cluster_{cluster[0]} {{", f"{indent}  {frame}"])
                emit(child, indent + "  ")
                lines.append(f"{indent}}}")
            else:
                emit(child, indent)
        for child in children:
            lines.append(f"{indent}{quote(node['id'])} -> {quote(child['id'])};")

    lines.append('  subgraph cluster_0 { label=""; peripheries=0;')
    emit(structure["root"], "    ")
    lines.extend(["  }", "}"])
    return "\n".join(lines) + "\n"



# ---------------------------------------------------------------------------- fuzzing
# Tree files of both formats, built from hostile parts: wrong types, NaN and infinities, huge
# and long numbers, lone surrogates, deep values, deep chains, references between trees and
# files (a FIFO among them), then sometimes cut or spliced as text. Every input must load (and
# then tick, halt, draw and serialise) or raise TreeLoadError whose problems are all located.
# Placeholders stand for what json.dumps cannot write (or would recurse on); _expand fills them.
_SPLICES = {"@@NAN@@": "NaN", "@@INF@@": "-Infinity", "@@E400@@": "1e400",
            "@@DIGITS@@": "9" * 1200, "@@SURROGATE@@": '"a\\udc00"'}
_SCALARS = st.one_of(
    st.none(), st.booleans(), st.integers(-(2 ** 70), 2 ** 70),
    st.floats(allow_nan=True, allow_infinity=True), st.text(max_size=6),
    st.sampled_from([10 ** 400, -(10 ** 400), -1, 0, 1, 2.5, "nan", "inf", "-Infinity",
                     "1e400", "9" * 400, "\ud800", "x\udfffy", *_SPLICES]))
_VALUES = st.recursive(_SCALARS, lambda inner: st.lists(inner, max_size=3)
                       | st.dictionaries(st.text(max_size=4), inner, max_size=3), max_leaves=6)
_DEEP = st.integers(0, 1300).map(lambda n: f"@@DEEP{n}@@")
_PROPERTY = st.sampled_from(["milliseconds", "maxLoop", "maxTime", "maxAttempts", "below",
                             "radius", "count", "successThreshold", "location", "time",
                             "value", "expr", "x"])
_PROPERTIES = st.dictionaries(_PROPERTY, _VALUES | _DEEP, max_size=3)
_TEXT = st.text(max_size=6) | st.sampled_from(["a\ud800", "<x> \udbff", "\U0001f916",
                                               "<value> <milliseconds>", "<expr><time>"])
_IDS = ["a", "b", "c", "d", "e"]
_TREES = ["t0", "t1", "t2"]
_NAMES = ["Sequence", "Priority", "MemSequence", "Parallel", "Inverter", "Repeater", "Wait",
          "Succeeder", "Failer", "Runner", "Timeout", "Limiter", "Retry", "MaxTime", "Below",
          *_TREES, "", "NoSuchNode"]
_V1_NAMES = ["Sequence", "Selector", "Parallel", "Invert", "AlwaysSuccess", "Wait", "Timeout",
             "JustSuccess", "JustFailure", "Check", "Let", "IfElse", "Once", "Repeat",
             "RetryUntilSuccess", "Race", "Delay", "Listen", "Nope", ""]


def _expand(text: str) -> str:
    """Fill the placeholders _SPLICES and _DEEP left in JSON text."""
    for marker, fragment in _SPLICES.items():
        text = text.replace(f'"{marker}"', fragment)
    while (start := text.find('"@@DEEP')) >= 0:
        end = text.index('@@"', start + 7)
        levels = int(text[start + 7:end])
        text = text[:start] + "[" * levels + "1" + "]" * levels + text[end + 3:]
    return text


@st.composite
def _node03(draw: st.DrawFn, node_id: str) -> dict[str, Any]:
    node: dict[str, Any] = {"id": draw(st.sampled_from([node_id] * 4 + [7, "other"]) | _DEEP),
                            "name": draw(st.sampled_from(_NAMES)), "title": draw(_TEXT),
                            "properties": draw(_PROPERTIES)}
    if draw(st.integers(0, 3)) == 0:  # the older name of properties
        node["parameters"] = draw(_PROPERTIES | _SCALARS)
    link = draw(st.sampled_from(["leaf", "child", "children", "bad"]))
    if link == "child":
        node["child"] = draw(st.sampled_from([*_IDS, "zz"]))
    elif link == "children":
        node["children"] = draw(st.lists(st.sampled_from([*_IDS, "zz"]), max_size=3))
    elif link == "bad":
        node[draw(st.sampled_from(["child", "children"]))] = draw(_SCALARS)
    return node


@st.composite
def _tree03(draw: st.DrawFn, tree_id: str) -> Any:
    ids = draw(st.lists(st.sampled_from(_IDS), min_size=1, max_size=5, unique=True))
    nodes = {node_id: draw(_node03(node_id)) for node_id in ids}
    root = draw(st.sampled_from([*ids, None, "zz"]))
    chain = draw(st.sampled_from([0, 0, 0, bt_limits.MAX_DEPTH - 3, bt_limits.MAX_DEPTH,
                                  1100]))
    if chain:  # a chain of decorators above the tree's own root
        nodes.update(_chain(chain, leaf=draw(st.sampled_from(_NAMES)))["nodes"])
        nodes[f"n{chain}"] = {"id": f"n{chain}", "name": "Inverter", "child": root}
        root = "n0"
    tree = {"id": draw(st.sampled_from([tree_id] * 5) | _DEEP), "title": draw(_TEXT),
            "root": root, "nodes": nodes, "properties": draw(_PROPERTIES)}
    return tree if draw(st.integers(0, 9)) else draw(_VALUES)


_NUMBER = st.integers(0, 9).flatmap(
    lambda k: _SCALARS if k == 0 else st.integers(1, 5) if k < 8 else st.floats(0, 2000))
_TAME_LEAVES = {"Succeeder": {}, "Failer": {}, "Runner": {}, "Wait": {"milliseconds": _NUMBER},
                "Below": {"below": _NUMBER, "radius": _NUMBER, "count": _NUMBER}}
_TAME_DECORATORS = {"Inverter": {}, "Repeater": {"maxLoop": _NUMBER},
                    "Timeout": {"milliseconds": _NUMBER}, "Limiter": {"maxLoop": _NUMBER},
                    "Retry": {"maxAttempts": _NUMBER}, "MaxTime": {"maxTime": _NUMBER}}


@st.composite
def _tame_node03(draw: st.DrawFn, node_id: str, choices: dict[str, dict[str, Any]],
                 ) -> dict[str, Any]:
    name = draw(st.sampled_from(sorted(choices)))
    properties = {key: draw(value) for key, value in choices[name].items()
                  if draw(st.integers(0, 5))}
    return {"id": node_id, "name": name, "title": draw(st.text(max_size=8)),
            "properties": properties}


@st.composite
def _tame_tree03(draw: st.DrawFn, tree_id: str, later: list[str]) -> dict[str, Any]:
    """A tree the engine should mostly accept: a composite over leaves (or references to the
    ``later`` trees), each maybe wrapped in a decorator, with plausible (sometimes hostile)
    numbers, maybe under a long chain."""
    leaves = {**_TAME_LEAVES, **{name: {} for name in later}}
    children: list[str] = []
    nodes: dict[str, Any] = {"root": {"id": "root", "name": draw(st.sampled_from(
        ["Sequence", "Priority", "MemSequence", "MemPriority", "Parallel"])),
        "children": children}}
    for index in range(draw(st.integers(1, 4))):
        leaf = draw(_tame_node03(f"l{index}", leaves))
        nodes[leaf["id"]] = leaf
        top = leaf["id"]
        if draw(st.booleans()):
            decorator = draw(_tame_node03(f"d{index}", _TAME_DECORATORS))
            decorator["child"] = leaf["id"]
            nodes[decorator["id"]] = decorator
            top = decorator["id"]
        children.append(top)
    root = "root"
    chain = draw(st.sampled_from([0, 0, 0, 0, 5, bt_limits.MAX_DEPTH - 9,
                                  bt_limits.MAX_DEPTH]))
    if chain:
        nodes.update(_chain(chain)["nodes"])
        nodes[f"n{chain}"] = {"id": f"n{chain}", "name": "Inverter", "child": root}
        root = "n0"
    return {"id": tree_id, "title": draw(st.text(max_size=6)), "root": root, "nodes": nodes}


@st.composite
def _file03(draw: st.DrawFn) -> str:
    count = draw(st.integers(1, 3))
    if draw(st.booleans()):  # tame: a project the engine should mostly load
        tame = [draw(_tame_tree03(tree_id, _TREES[index + 1:count]))
                for index, tree_id in enumerate(_TREES[:count])]
        return json.dumps({"trees": tame, "selectedTree": "t0"}, indent=1)
    trees: list[Any] = [draw(st.one_of(_tame_tree03(tree_id, _TREES), _tree03(tree_id)))
             for tree_id in _TREES[:count]]
    shape = draw(st.sampled_from(["project", "project", "tree", "desktop", "nodes"]))
    data: Any
    if shape == "tree" and isinstance(trees[0], dict):
        data = {"scope": "tree", **trees[0]}
    elif shape == "nodes":
        data = draw(st.lists(st.fixed_dictionaries({"name": _TEXT, "category": _TEXT}),
                             max_size=3))
    else:
        data = {"trees": trees, "selectedTree": draw(st.sampled_from([*_TREES, None, 5])),
                "custom_nodes": draw(st.lists(_VALUES | _DEEP, max_size=2))}
        data = {"name": "p", "data": data} if shape == "desktop" else data
    return _mutate(draw, _expand(json.dumps(data, indent=draw(st.sampled_from([None, 1])))))


def _mutate(draw: st.DrawFn, text: str) -> str:
    """Sometimes cut, splice into or repeat part of ``text``."""
    how = draw(st.sampled_from(["none"] * 6 + ["cut", "insert", "drop"]))
    if how == "none" or not text:
        return text
    at = draw(st.integers(0, len(text) - 1))
    if how == "cut":
        return text[:at]
    if how == "insert":
        return text[:at] + draw(st.sampled_from(['"', "{", "]", ",", "\\ud800", "9" * 1100,
                                                  "\x00", "\ufeff"])) + text[at:]
    return text[:at] + text[at + draw(st.integers(1, 20)):]


@st.composite
def _node_v1(draw: st.DrawFn, depth: int = 0) -> dict[str, Any]:
    node: dict[str, Any] = {
        "id": draw(st.one_of(st.integers(-3, 40), st.text(max_size=3), _DEEP,
                             st.sampled_from([None, True, 10 ** 400]))),
        "name": draw(st.sampled_from(_V1_NAMES)), "desc": draw(_TEXT)}
    for key, strategy in (("args", _PROPERTIES | _SCALARS),
                          ("input", st.lists(st.sampled_from(["a", "b", ""]), max_size=2)
                           | _SCALARS),
                          ("output", st.lists(st.sampled_from(["a", "c"]), max_size=2)),
                          ("disabled", st.booleans()),
                          ("path", st.sampled_from(["sub.json", "fifo.json", "missing.json",
                                                    "main.json", "deep.json", "", 5]))):
        if draw(st.integers(0, 3)) == 0:
            node[key] = draw(strategy)
    if depth < 3 and draw(st.booleans()):
        node["children"] = [draw(_node_v1(depth + 1)) for _ in range(draw(st.integers(0, 3)))]
    return node


_TAME_V1 = {"JustSuccess": {}, "JustFailure": {}, "Wait": {"time": _NUMBER},
            "Check": {"value": st.sampled_from(["a > 1", "b", "c.d[0] + 'x'", "1 / 0"])},
            "Let": {"value": _VALUES}, "Sequence": {}, "Selector": {}, "Parallel": {},
            "Invert": {}, "AlwaysSuccess": {}, "Once": {}, "Repeat": {"count": _NUMBER},
            "Timeout": {"time": _NUMBER}, "Race": {}, "IfElse": {}}


@st.composite
def _tame_v1(draw: st.DrawFn, depth: int = 0, subtree: bool = True) -> dict[str, Any]:
    """A v1 node the engine should mostly accept (ids made unique when the file is written);
    ``subtree``: it may reference ``sub.json``."""
    leaf = depth >= 3
    name = draw(st.sampled_from(sorted(k for k in _TAME_V1 if not leaf or not _ARITY.get(k))))
    node: dict[str, Any] = {"id": 0, "name": name, "args": {
        key: draw(value) for key, value in _TAME_V1[name].items() if draw(st.integers(0, 5))}}
    if name == "Check" and draw(st.booleans()):
        node["input"] = ["a"]
    if name == "Let":
        node["output"] = ["a"]
    low, high = _ARITY.get(name, (0, 0))
    if high:
        node["children"] = [draw(_tame_v1(depth + 1, subtree))
                            for _ in range(draw(st.integers(low, high)))]
    elif subtree and draw(st.integers(0, 5)) == 0:
        node = {"id": 0, "name": "Sequence", "path": "sub.json"}
    return node


_ARITY = {"Sequence": (1, 3), "Selector": (1, 3), "Parallel": (1, 3), "Race": (1, 3),
          "IfElse": (2, 3), "Invert": (1, 1), "AlwaysSuccess": (1, 1), "Once": (1, 1),
          "Repeat": (1, 1), "Timeout": (1, 1)}


def _numbered(node: dict[str, Any], ids: Iterator[int]) -> dict[str, Any]:
    """``node`` with fresh ids given depth first (its children lists are shallow)."""
    pending = [node]
    while pending:
        item = pending.pop()
        item["id"] = next(ids)
        pending.extend(child for child in item.get("children", []) if isinstance(child, dict))
    return node


@st.composite
def _files_v1(draw: st.DrawFn) -> dict[str, str]:
    """File name -> text (``None`` text: make a FIFO) of a v1 workdir; ``main.json`` is run."""
    tame = draw(st.booleans())  # files the engine should mostly load

    def tree_text(subtree: bool = True) -> str:
        if tame:
            return json.dumps({"name": "t", "root": _numbered(draw(_tame_v1(0, subtree)),
                                                            itertools.count(1))})
        root = draw(st.one_of(_tame_v1().map(lambda n: _numbered(n, itertools.count(1))),
                              _node_v1()))
        data = {"name": draw(_TEXT), "root": root,
                **draw(st.dictionaries(st.sampled_from(["vars", "import", "version"]),
                                       _VALUES | st.just(["vars.json"]), max_size=2))}
        return _mutate(draw, _expand(json.dumps(data)))

    levels = draw(st.sampled_from([1, 10, bt_limits.MAX_DEPTH, 1200]))
    deep = "".join(f'{{"id": {i}, "name": "Invert", "children": [' for i in range(levels))
    files = {"main.json": tree_text(), "sub.json": tree_text(subtree=False),
             "deep.json": '{"root": ' + deep + '{"id": "x", "name": "Wait"}' + "]}" * levels
             + "}",
             "vars.json": _expand(json.dumps({"vars": draw(_VALUES), "import": ["vars.json"]}))}
    if draw(st.booleans()):
        files["node-config.b3-setting"] = _expand(json.dumps(draw(st.lists(
            st.fixed_dictionaries({"name": st.sampled_from(_V1_NAMES), "type": _TEXT,
                                   "args": _VALUES}), max_size=3))))
    return files


def _exercise(load: Callable[[], Tree]) -> str:
    """Load; on success tick, draw, serialise and halt the tree; on failure check the
    problems are located. Returns what happened, for hypothesis' statistics."""
    try:
        tree = load()
    except TreeLoadError as exc:
        assert exc.problems
        for problem in exc.problems:
            assert_located(problem)
        str(exc).encode("utf-8")
        return "refused"
    for _ in range(3):
        tree.tick()
        assert isinstance(tree.clock, ManualClock)
        tree.clock.advance(0.5)
    tree.to_dot().encode("utf-8")
    json.dumps(tree.structure.to_json(), ensure_ascii=False).encode("utf-8")
    tree.halt()
    return "loaded"


_FUZZ = settings(max_examples=150, deadline=5000,
                 suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])


@_FUZZ
@given(text=_file03(), stub=st.sampled_from([None, Status.SUCCESS, Status.RUNNING]),
       max_nodes=st.sampled_from([None, 40]))
def test_fuzz_behavior3editor_files(text: str, stub: Status | None,
                                    max_nodes: int | None) -> None:
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "tree.b3.json"
        path.write_text(text, encoding="utf-8", errors="surrogatepass")
        registry = _registry()
        event(str(_bounded(lambda: _exercise(lambda: load_tree(
            path, registry=registry, clock=ManualClock(), stub_missing=stub,
            max_nodes=max_nodes)))))
        _bounded(lambda: _exercise(lambda: loads_tree(
            text, registry=registry, clock=ManualClock(), stub_missing=stub)))
        problems = _bounded(lambda: check_file(path, registry=registry, stub_missing=stub))
        assert isinstance(problems, list)
        for problem in problems:
            assert_located(problem)


@_FUZZ
@given(files=_files_v1(), fifo=st.booleans(), stub=st.sampled_from([None, Status.SUCCESS]))
def test_fuzz_behavior3_v1_workdirs(files: dict[str, str], fifo: bool,
                                    stub: Status | None) -> None:
    with tempfile.TemporaryDirectory() as folder:
        workdir = Path(folder)
        (workdir / "robot.b3-workspace").write_text("{}")
        for name, text in files.items():
            (workdir / name).write_text(text, encoding="utf-8", errors="surrogatepass")
        if fifo and hasattr(os, "mkfifo"):
            os.mkfifo(workdir / "fifo.json")
        main = workdir / "main.json"
        event(str(_bounded(lambda: _exercise(lambda: load_tree(main, clock=ManualClock(),
                                                               stub_missing=stub)))))
        problems = _bounded(lambda: check_file(main, stub_missing=stub))
        assert isinstance(problems, list)
        for problem in problems:
            assert_located(problem)
