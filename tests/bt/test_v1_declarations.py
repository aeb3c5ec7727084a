"""What behavior3 v1's stock nodes are in cyborg, and the checks made when they are loaded.

Every stock node of behavior3-ts, behavior3lua and the editor's sample has a cyborg node (of
its name, or an equivalent of cyborg.bt.editor_v1_names) or says why not; ports match
behavior3-ts's declarations position by position; and a node with a bad expression, a wrong
number of children, an unknown op or an unbound port is a load error that names the node.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from cyborg.bt.editor_v1_names import EQUIVALENTS, NO_EQUIVALENT, REPLACED_IN_CYBORG
from tests.bt.v1_samples import SAMPLES, TS_EXAMPLE, calc, check, load, load_error, n, s
from tests.builders import registry


# --------------------------------------------------------------------------- load errors
@pytest.mark.parametrize(("root", "fragment"), [
    (check("hp >> > 3"), "Check(value='hp >> > 3') raised ExpressionError: in 'hp >> > 3': "
                         "expected a value but found '>' at column 7"),
    (calc("a +", "b"), "Calculate(value='a +') raised ExpressionError"),
    (n("Cmp", args={"value": "(", "gt": 1}, i=[""]), "Cmp(value='(', gt=1.0) raised"),
    (n("Cmp", i=["hp"]), "Cmp needs one of the args gt, ge, eq, lt, le"),
    (n("IfElse", n("JustSuccess")), "IfElse takes 2 or 3 children, not 1"),
    (n("Watchdog", n("JustSuccess"), n("JustSuccess")), "Watchdog takes 3 children, not 2"),
    (n("Case", n("JustSuccess")), "Case takes 2 children, not 1"),
    (n("Switch", n("JustSuccess")), "Switch takes only Case children; child 1 is a Succeeder"),
    (n("Math", args={"op": "cube"}), "unknown op 'cube'; Math knows abs, ceil"),
    (n("Index", i=["", ""], o=["v"]), "input port 'array' is not bound"),
])
def test_bad_nodes_are_load_errors_that_name_the_node(root: dict[str, Any],
                                                      fragment: str) -> None:
    message = load_error(root)
    assert fragment in message
    assert f"(id {root['id']})" in message


# --------------------------------------------------------------------------- names
def _stock_names(setting: Path) -> list[str]:
    test_only = {"Attack", "FindEnemy", "GetHp", "Idle", "IsStatus", "MoveToPos",
                 "MoveToTarget", "TestB3", "TestOneof"}
    names = [item["name"] for item in json.loads(setting.read_text(encoding="utf-8"))]
    return [name for name in names if name not in test_only]


@pytest.mark.parametrize("setting", [
    TS_EXAMPLE / "node-config.b3-setting",
    SAMPLES / "behavior3lua-workspace" / "node-config.b3-setting",
    SAMPLES / "editor-sample" / "node-config.b3-setting",
], ids=["behavior3-ts", "behavior3lua", "editor-sample"])
def test_every_v1_stock_node_has_a_cyborg_node_or_says_why_not(setting: Path) -> None:
    reg = registry()
    for name in _stock_names(setting):
        target = EQUIVALENTS[name].name if name in EQUIVALENTS else name
        if name in NO_EQUIVALENT:
            assert target not in reg or name in REPLACED_IN_CYBORG, name
        else:
            node_type = reg.get(target)
            assert node_type is not None and node_type.origin == "stock", name


PORTS_NOT_READ = {"Wait", "Timeout"}
"""cyborg's own Wait and Timeout do not read behavior3-ts's optional time input (see the docs)."""


def test_ports_match_behavior3_ts_declarations_position_by_position() -> None:
    """Same count of inputs and outputs, and the same optional (?) and repeated (...) marks,
    so that a file's input/output arrays bind the same slots."""
    def marks(ports: list[str] | tuple[str, ...]) -> list[str]:
        return ["..." if p.endswith("...") else "?" if p.endswith("?") else "" for p in ports]

    reg = registry()
    definitions = json.loads((TS_EXAMPLE / "node-config.b3-setting").read_text("utf-8"))
    checked = 0
    for definition in definitions:
        name = definition["name"]
        node_type = reg.get(EQUIVALENTS[name].name if name in EQUIVALENTS else name)
        if node_type is None or name in PORTS_NOT_READ or name in NO_EQUIVALENT:
            continue
        declared = (marks(definition.get("input") or []), marks(definition.get("output") or []))
        assert (marks(node_type.cls.inputs), marks(node_type.cls.outputs)) == declared, name
        checked += 1
    assert checked >= 35


def test_the_v1_parallel_is_not_cyborgs_parallel() -> None:
    tree, _ = load(n("Parallel", s("S", "a")))
    assert type(tree.nodes[1]).__name__ == "ParallelAll"
    assert EQUIVALENTS["Parallel"].name == "ParallelAll"
