"""Hostile tree files that expand into too many nodes (issue 19, items 8 and 10).

Trees that reference the next one twice, 20 levels deep (2^20 instances), stop at the node cap
within seconds with a located error naming it; the cap is a parameter; a big subtree shared by
many trees is built once when a file is checked; v1 subtree files doubling up stop at the cap
too.
"""

from __future__ import annotations

import json
import time
from pathlib import Path

from cyborg.bt import check_file, load_tree, loads_tree
from cyborg.bt import limits as bt_limits
from tests.bt.hostile_helpers import _bounded, _chain, _doubling, _errors, _tree, _v1


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
