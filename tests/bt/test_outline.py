"""A structure's JSON read back as a flat pre-order outline (shared by the monitor and report)."""

from __future__ import annotations

import json

import pytest

from cyborg.bt.outline import StructureError, StructureOutline
from tests.builders import N, tree_from


def test_the_outline_lists_nodes_in_pre_order_with_parents_depths_and_labels() -> None:
    tree = tree_from(N("Sequence", N("Scripted", id="a", title="First"),
                       N("Inverter", N("Scripted", id="b", script="F")), id="seq"))
    outline = StructureOutline.parse(json.dumps(tree.structure.to_json()))
    assert outline.ids[1:] == ["seq", "a", outline.ids[3], "b"]
    assert outline.parents == [-1, 0, 1, 1, 3]
    assert outline.depths == [0, 1, 2, 2, 3]
    assert outline.labels[2] == "First"
    assert outline.categories[1] == "composite"
    assert outline.index_of["b"] == 4 and len(outline) == 5


def test_a_structure_as_deep_as_a_loaded_tree_may_be_is_read() -> None:
    outline = StructureOutline.parse(_deep_text(301))  # 2 x 150 + 1 levels, docs/tree-structure
    assert len(outline) == 302 and outline.depths[-1] == 301
    assert outline.parents[-1] == 300


def _deep_text(levels: int) -> str:
    """A chain of ``levels`` nodes above a leaf, as text (json.dumps would recurse)."""
    opening = "".join(f'{{"id":"n{level}","children":[' for level in range(levels))
    return '{"root":' + opening + '{"id":"leaf","children":[]}' + "]}" * levels + "}"


@pytest.mark.parametrize("text, said", [
    ("not json", "not a tree structure"),
    ('{"tree": {}}', "not a tree structure"),
    ('{"root": {"name": "x"}}', "node 0 has no 'id'"),
    ('{"root": {"id": "r", "children": [3]}}', "node 1 has no"),
])
def test_what_is_no_structure_is_refused_saying_why(text: str, said: str) -> None:
    with pytest.raises(StructureError, match=said):
        StructureOutline.parse(text)
