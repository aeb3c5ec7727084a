"""Reading a tree's structure for its ticks: pre-order nodes with titles; bad structures said."""

from __future__ import annotations

import json

import pytest

from cyborg.foxglove.tree_relay import status_label, structure_nodes
from tests.builders import N, tree_from


def test_the_structure_gives_its_nodes_in_pre_order_with_their_titles() -> None:
    tree = tree_from(N("Sequence", N("Scripted", id="a", title="First <x>", x=3),
                       N("Scripted", id="b"), id="s"))
    header, nodes = structure_nodes(json.dumps(tree.structure.to_json()))
    assert header["tree_id"] == "main" and header["title"] == "Main"
    assert [node["id"] for node in nodes][1:] == ["s", "a", "b"]  # after the tree's own node
    assert nodes[2]["title"] == "First 3"  # placeholders filled in, as the editor shows it


@pytest.mark.parametrize(("text", "reason"), [
    ("not json", "behavior_tree is not a tree structure"),
    ('{"tree_id": "x"}', "behavior_tree is not a tree structure: 'root'"),
    ('{"root": {"children": []}}', "behavior_tree: node 0 has no id"),
    ('{"root": {"id": "r", "children": [3]}}', "behavior_tree: node 1 has no id"),
])
def test_a_structure_that_is_not_one_is_refused_naming_it(text: str, reason: str) -> None:
    with pytest.raises(ValueError, match=reason):
        structure_nodes(text)


def test_statuses_are_named_as_the_engine_names_them() -> None:
    assert [status_label(code) for code in (0, 1, 2, 3, 4, 9)] == [
        "idle", "success", "failure", "running", "error", "idle"]
