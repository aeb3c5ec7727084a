"""Hostile tree files on disk (issue 19, items 8 and 10): what is not a regular file, and size.

FIFOs (the tree file itself, or a v1 subtree, import or node settings file) and folders are
refused at once; files over the size cap are refused before they are read, counting the files
a v1 tree references (a subtree file used many times is read once); and the caps can be raised
from the environment.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

from cyborg.bt import TreeLoadError, check_file, load_tree, loads_tree
from cyborg.bt import limits as bt_limits
from tests.bt.hostile_helpers import _bounded, _chain, _doubling, _errors, _v1


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
