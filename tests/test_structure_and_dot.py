"""The structure export follows its JSON schema; DOT export is valid Graphviz."""

from __future__ import annotations

import html
import json
import shutil
import subprocess
from importlib.resources import files
from pathlib import Path
from typing import Any

import jsonschema
import pytest

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
    assert svg.count("<g id=\"clust") == references, "one cluster per subtree reference"


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
