"""The structure export follows its JSON schema; DOT export is valid Graphviz."""

from __future__ import annotations

import html
import json
import shlex
import shutil
import subprocess
from importlib.resources import files
from pathlib import Path
from typing import Any

import jsonschema
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cyborg.bt import ManualClock, Status, load_tree
from cyborg.bt.dot import structure_to_dot
from tests.builders import N, tree_from
from tests.conftest import shared_dir

SHARED_TREES = shared_dir() / "trees"


def _schema() -> dict[str, Any]:
    text = files("cyborg.bt").joinpath("structure.schema.json").read_text()
    schema: dict[str, Any] = json.loads(text)
    return schema


def _bundled_tree_path() -> Path:
    return Path(str(files("cyborg.app").joinpath("data", "campus_patrol.b3.json")))


@pytest.mark.parametrize("path", [
    _bundled_tree_path(), SHARED_TREES / "stock_nodes.tree.json",
    SHARED_TREES / "patrol_recharge.b3.json",
], ids=lambda p: p.name)
def test_structure_matches_schema(path: Path) -> None:
    tree = load_tree(path, clock=ManualClock())
    structure = tree.structure.to_json()
    jsonschema.validate(structure, _schema())
    assert structure["node_count"] == len(tree)
    ids = []

    def walk(node: dict[str, Any]) -> None:
        ids.append(node["id"])
        for child in node["children"]:
            walk(child)

    walk(structure["root"])
    assert ids == [node.uid for node in tree], "pre-order, one entry per node"
    assert len(set(ids)) == len(ids)


def test_structure_fields() -> None:
    tree = tree_from(N("Inverter", N("Wait", id="w", title="Wait <milliseconds>ms",
                                     milliseconds=5), id="inv"))
    root = tree.structure.to_json()["root"]
    assert root["category"] == "tree" and root["tree_id"] == "main"
    inverter = root["children"][0]
    assert (inverter["id"], inverter["category"], inverter["depth"]) == ("inv", "decorator", 0)
    wait = inverter["children"][0]
    assert wait == {"id": "w", "node_id": "w", "name": "Wait", "title": "Wait <milliseconds>ms",
                    "label": "Wait 5ms", "category": "action", "depth": 0, "index": 2,
                    "properties": {"milliseconds": 5}, "children": []}


def test_snapshot_json() -> None:
    tree = tree_from(N("Sequence", N("Succeeder", id="ok"), N("Runner", id="run"), id="seq"))
    data = tree.tick().to_json()
    assert data["tick"] == 1 and data["status"] == "running"
    assert data["visited"] == [["ok", "success"], ["run", "running"], ["seq", "running"],
                               ["main", "running"]]
    assert data["active"] == ["main", "seq", "run"]
    assert data["halted"] == []
    json.dumps(data)


def _dot_binary() -> str:
    dot = shutil.which("dot")
    assert dot is not None, "Graphviz 'dot' must be installed (scripts/test.sh installs it)"
    return dot


def test_dot_renders_with_graphviz(tmp_path: Path) -> None:
    tree = load_tree(_bundled_tree_path(), clock=ManualClock())
    snapshot = tree.tick()
    text = structure_to_dot(tree.structure.to_json(),
                            statuses={uid: s.label for uid, s in snapshot.visited},
                            active=snapshot.active)
    result = subprocess.run([_dot_binary(), "-Tsvg"], input=text, capture_output=True,
                            text=True, check=False)
    assert result.returncode == 0, result.stderr
    svg = result.stdout
    text_in_svg = html.unescape(svg)
    for node in tree:
        assert f">{node.label}</text>" in text_in_svg
    references = sum(node.category.value == "tree" for node in tree) - 1  # not the root tree
    assert references == 2
    framed = svg.count('<polygon fill="none" stroke="#9aa0a6" stroke-dasharray')
    assert framed == references, "one dashed frame per subtree reference"


def _laid_out(text: str) -> dict[str, tuple[float, float]]:
    """Node id -> (x, y) of Graphviz's layout of DOT ``text`` (``dot -Tplain``)."""
    result = subprocess.run([_dot_binary(), "-Tplain"], input=text, capture_output=True,
                            text=True, check=True)
    positions = {}
    for line in result.stdout.splitlines():
        fields = shlex.split(line)
        if fields[0] == "node":
            positions[fields[1]] = (float(fields[2]), float(fields[3]))
    return positions


def _out_of_order(node: dict[str, Any], positions: dict[str, tuple[float, float]],
                  rankdir: str) -> list[str]:
    """Parents whose children are not laid out in tick order (left to right; top to bottom
    when the drawing runs left to right)."""
    children = node.get("children", [])
    if rankdir == "TB":
        along = [positions[child["id"]][0] for child in children]
    else:  # -Tplain's y grows upwards
        along = [-positions[child["id"]][1] for child in children]
    wrong = [] if along == sorted(along) and len(set(along)) == len(along) else [node["label"]]
    for child in children:
        wrong += _out_of_order(child, positions, rankdir)
    return wrong


def test_dot_export_draws_children_in_tick_order() -> None:
    """The shared patrol tree: CheckBattery (tick first) is drawn left of Patrol."""
    tree = load_tree(SHARED_TREES / "patrol_recharge.b3.json", clock=ManualClock())
    structure = tree.structure.to_json()
    priority = structure["root"]["children"][0]
    assert [child["label"] for child in priority["children"]] == ["CheckBattery 25",
                                                                  "Patrol tree"]
    for rankdir in ("TB", "LR"):
        text = structure_to_dot(structure, rankdir=rankdir)
        assert _out_of_order(structure["root"], _laid_out(text), rankdir) == [], rankdir


@st.composite
def _structures(draw: st.DrawFn, depth: int = 0) -> dict[str, Any]:
    category = draw(st.sampled_from(["composite", "decorator", "tree", "action"])
                    if depth < 4 else st.just("action"))
    count = {"composite": draw(st.integers(1, 4)), "decorator": 1, "tree": 1,
             "action": 0}[category]
    children = [draw(_structures(depth + 1)) for _ in range(count)]
    return {"id": "", "label": "", "name": "", "category": category, "children": children}


def _numbered(node: dict[str, Any], counter: list[int]) -> dict[str, Any]:
    counter[0] += 1
    uid = f"n{counter[0]}"
    children = [_numbered(child, counter) for child in node["children"]]
    return {**node, "id": uid, "label": uid, "name": uid, "children": children}


@settings(max_examples=40, deadline=None)
@given(root=_structures(), rankdir=st.sampled_from(["TB", "LR"]))
def test_every_laid_out_tree_keeps_tick_order(root: dict[str, Any], rankdir: str) -> None:
    root = _numbered(root, [0])
    text = structure_to_dot({"title": "t", "root": root}, rankdir=rankdir)
    assert _out_of_order(root, _laid_out(text), rankdir) == []


def test_dot_quotes_awkward_labels() -> None:
    tree = tree_from(N("Sequence", N("Succeeder", id='q"1', title='Say "hi" \\ bye'), id="s"))
    text = tree.to_dot()
    assert '"q\\"1"' in text and 'label="Say \\"hi\\" \\\\ bye"' in text
    result = subprocess.run([_dot_binary(), "-Tplain"], input=text, capture_output=True,
                            text=True, check=False)
    assert result.returncode == 0, result.stderr


def test_status_colours_in_dot() -> None:
    tree = tree_from(N("Sequence", N("Failer", id="f"), id="s"))
    snapshot = tree.tick()
    assert snapshot.status is Status.FAILURE
    text = structure_to_dot(tree.structure.to_json(),
                            statuses={uid: s.label for uid, s in snapshot.visited})
    assert '"f" [label="Failer", shape=box, style="rounded,filled", fillcolor="#f28b82"]' in text
