"""Hostile tree files nested too deeply (issue 19, items 8 and 10), and deep trees walked.

Chains of nodes, decorators, subtree references, v1 subtree files and v1 imports past the
depth cap are refused with a located error naming the cap, never a RecursionError; the deepest
tree accepted still loads and ticks with room left on the stack; and walking, describing and
drawing a deep tree built in Python do not recurse.
"""

from __future__ import annotations

import itertools
import json
import sys
from pathlib import Path
from typing import Any

import pytest

from cyborg.bt import (
    Blackboard,
    Inverter,
    ManualClock,
    Status,
    Succeeder,
    Tree,
    TreeLoadError,
    check_file,
    load_tree,
    loads_tree,
)
from cyborg.bt import limits as bt_limits
from cyborg.bt.dot import structure_to_dot
from cyborg.bt.node import TickRecord
from tests.bt.hostile_helpers import (
    Deep,
    _bounded,
    _chain,
    _doubling,
    _errors,
    _registry,
    _tree,
    _v1,
)


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
