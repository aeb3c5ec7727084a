"""The blackboard's three scopes, and reading it whole."""

from __future__ import annotations

from cyborg.bt import Blackboard
from tests.builders import N, tree_from


def test_scopes_are_separate() -> None:
    board = Blackboard({"locations": {"home": (0.0, 0.0)}})
    board.set("k", "global")
    board.set("k", "tree", tree="t1")
    board.set("k", "node", node="n1")
    assert board.get("k") == "global" and board["k"] == "global"
    assert board.get("k", tree="t1") == "tree"
    assert board.get("k", node="n1") == "node"
    assert board.get("k", tree="t2") is None
    assert board.get("missing", "fallback") == "fallback"
    assert set(board) == {"locations", "k"} and len(board) == 2
    del board["k"]
    assert "k" not in board


def test_as_dict_shows_all_scopes_including_stock_node_memory() -> None:
    tree = tree_from(N("MemSequence", N("Succeeder", id="a"), N("Wait", id="w",
                                                                 milliseconds=100), id="m"))
    tree.blackboard["battery"] = 80
    tree.tick()
    view = tree.blackboard.as_dict()
    assert view["global"]["battery"] == 80
    assert view["nodes"]["m"] == {"running_child": 1}
    assert view["nodes"]["w"] == {"start": 0.0}
    assert "a" not in view["nodes"], "empty node scopes are left out"
    view["global"]["battery"] = 0
    assert tree.blackboard["battery"] == 80, "as_dict returns a copy"
