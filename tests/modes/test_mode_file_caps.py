"""One mode file is one load: its modes, trees and subtrees together keep the loader's caps.

Twenty modes naming one tree of 60,000 nodes built 1.2 million nodes (1.6 GB, 66 s); 3,000
modes loaded in 39 s and a chain of 5,000 in 55 s. A tree several modes name is now built once,
the trees share one node budget and the files one byte budget, and a file has at most so many
modes, transitions and listed problems.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from cyborg.bt import Blackboard, ManualClock
from cyborg.bt.problems import Problem
from cyborg.modes import ModeFileError, caps, load_machine, parse_mode_file, read_mode_file
from cyborg.modes.mode_file import mode_file_limits
from tests.builders import N, project_json, registry, tree_json
from tests.modes.machines import events, machine, write_modes, write_project
from tests.modes.test_mode_file import line_of
from tests.modes.test_schema_and_docs import doc_blocks


def wide(tree: str, nodes: int) -> dict[str, object]:
    """A tree whose id and title are ``tree``: a Sequence over Succeeders, ``nodes`` in all."""
    return tree_json(N("Sequence", *[N("Succeeder") for _ in range(nodes - 1)]),
                     tree_id=tree, title=tree)


def modes_text(trees: dict[str, str], *, project: str = '"wide.b3.json"',
               key: str = "project") -> str:
    """A mode file whose modes (``name -> tree``) a request leads to from the first one."""
    names = list(trees)
    lines = [f"{key} = {project}", f'initial = "{names[0]}"']
    for name, tree in trees.items():
        lines += [f"[modes.{name}]", f'tree = "{tree}"']
    for name in names[1:]:
        lines += ["[[transitions]]", f'from = "{names[0]}"', f'to = "{name}"',
                  "on_request = true"]
    return "\n".join(lines) + "\n"


def refused(path: Path, *, max_bytes: int | None = None,
            max_nodes: int | None = None) -> list[Problem]:
    """The problems of loading the mode file at ``path``, which must not load."""
    with pytest.raises(ModeFileError) as caught:
        load_machine(path, registry=registry(), clock=ManualClock(), max_bytes=max_bytes,
                     max_nodes=max_nodes)
    return caught.value.problems


def test_modes_naming_one_tree_share_one_instance_counted_once(tmp_path: Path) -> None:
    """Three modes name one tree of 61 instances (by id and by title); 100 nodes are enough."""
    (tmp_path / "wide.b3.json").write_text(project_json([wide("big", 60), wide("small", 2)]))
    text = modes_text({"a": "big", "b": "big", "c": "small", "d": "big"})
    m = load_machine(write_modes(tmp_path, text), registry=registry(), clock=ManualClock(),
                     max_nodes=100)
    assert m.trees["a"] is m.trees["b"] is m.trees["d"]
    assert m.trees["c"] is not m.trees["a"] and len(m.trees["a"]) == 61
    assert m.request("b").accepted and m.mode == "b"
    m.tick()


def test_switching_between_two_modes_of_one_tree_halts_it_and_starts_it_fresh(
        tmp_path: Path) -> None:
    text = """project = "mission.b3.json"
initial = "a"
[modes.a]
tree = "patrol"
[modes.b]
tree = "patrol"
[[transitions]]
from = "a"
to = "b"
on_request = true
"""
    m = machine(tmp_path, text, {"patrol": "R"})
    assert m.trees["a"] is m.trees["b"]
    m.tick()
    m.tree.blackboard.tree_scope(m.tree.root.uid)["left"] = "by a"
    assert m.request("b").accepted
    assert not any(m.tree.blackboard.trees.values())
    m.tick()
    assert events(m) == [("start", "patrol"), ("tick", "patrol"), ("halt", "patrol"),
                         ("start", "patrol"), ("tick", "patrol")]


def test_the_trees_of_all_modes_share_one_node_budget(tmp_path: Path,
                                                      monkeypatch: pytest.MonkeyPatch) -> None:
    """Two different trees of 61 instances each pass a cap of 100 alone, not together."""
    (tmp_path / "wide.b3.json").write_text(project_json([wide("one", 60), wide("two", 60)]))
    text = modes_text({"a": "one", "b": "one", "c": "two"})
    path = write_modes(tmp_path, text)
    for problems in (refused(path, max_nodes=100),
                     _with_environment(monkeypatch, "CYBORG_TREE_MAX_NODES", "100", path)):
        assert len(problems) == 1, [str(p) for p in problems]
        problem = problems[0]
        assert problem.source == str(path) and problem.line == line_of(text, "[modes.c]")
        assert "mode 'c'" in problem.message and "'two' makes 61 node instances" in problem.message
        assert "that is 122, more than the 100" in problem.message
    assert "max_nodes=N" in str(refused(path, max_nodes=100)[0])


def _with_environment(monkeypatch: pytest.MonkeyPatch, variable: str, value: str,
                      path: Path) -> list[Problem]:
    """The problems of ``path`` with ``variable`` set to ``value``."""
    with monkeypatch.context() as patch:
        patch.setenv(variable, value)
        problems = refused(path)
    return problems


def test_one_tree_past_the_budget_is_refused_before_it_is_built(tmp_path: Path) -> None:
    (tmp_path / "wide.b3.json").write_text(project_json([wide("big", 200)]))
    path = write_modes(tmp_path, modes_text({"a": "big"}))
    problem, = refused(path, max_nodes=100)
    assert "makes more than 100 node instances" in problem.message
    assert problem.line == 3 and problem.field == "tree"


def test_the_mode_file_and_every_file_it_names_share_one_byte_budget(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    for name in ("one", "two"):
        (tmp_path / f"{name}.b3.json").write_text(project_json([wide(name, 20)]))
    size = (tmp_path / "one.b3.json").stat().st_size
    text = modes_text({"a": "one", "b": "two"}, key="files",
                      project='["one.b3.json", "two.b3.json"]')
    path = write_modes(tmp_path, text)
    cap = size + len(text.encode()) + size // 2  # the mode file and one tree file, not two
    load_machine(path, registry=registry(), clock=ManualClock(), max_bytes=2 * cap)
    for problems in (refused(path, max_bytes=cap),
                     _with_environment(monkeypatch, "CYBORG_TREE_MAX_BYTES", str(cap), path)):
        ours = [p for p in problems if p.source == str(path)]
        assert ours[0].line == 1 and all(p.line is not None for p in ours)
        assert "'files' names 'two.b3.json', which does not load" in ours[0].message
        theirs = [p for p in problems if p.source.endswith("two.b3.json")]
        assert theirs and "read from the files before it" in theirs[0].message


def test_a_file_named_twice_is_read_once_and_its_trees_are_not_ambiguous(
        tmp_path: Path) -> None:
    write_project(tmp_path, {"patrol": "R", "charge": "R"})
    text = modes_text({"a": "patrol", "b": "charge", "c": "patrol"}, key="files",
                      project='["mission.b3.json", "./mission.b3.json"]')
    spec = read_mode_file(write_modes(tmp_path, text))
    assert spec.modes["a"].project is spec.modes["c"].project is spec.modes["b"].project
    m = load_machine(write_modes(tmp_path, text), registry=registry(), clock=ManualClock(),
                     blackboard=Blackboard({"events": []}))
    assert m.trees["a"] is m.trees["c"]


def test_more_modes_than_the_cap_are_refused_at_the_first_past_it(tmp_path: Path) -> None:
    """3,000 modes took 39 s to load; past MAX_MODES none of them is read."""
    write_project(tmp_path, {"patrol": "R"})
    names = {f"m{i}": "patrol" for i in range(caps.MAX_MODES + 1)}
    text = modes_text(names, project='"mission.b3.json"')
    problem, = refused(write_modes(tmp_path, text))
    assert problem.line == line_of(text, f"[modes.m{caps.MAX_MODES}]")
    assert f"declares {caps.MAX_MODES + 1} modes, more than the {caps.MAX_MODES}" \
        in problem.message and f"mode 'm{caps.MAX_MODES}'" in problem.message


def test_more_transitions_than_the_cap_are_refused_at_the_first_past_it(
        tmp_path: Path) -> None:
    write_project(tmp_path, {"patrol": "R"})
    text = modes_text({"a": "patrol", "b": "patrol"}, project='"mission.b3.json"')
    text += "".join(f'[[transitions]]\nfrom = "a"\nto = "b"\nevent = "e{i}"\n'
                    for i in range(caps.MAX_TRANSITIONS))
    problem, = refused(write_modes(tmp_path, text))
    assert problem.line == line_of(text, "[[transitions]]", caps.MAX_TRANSITIONS + 1)
    assert f"transition {caps.MAX_TRANSITIONS + 1} is the first past it" in problem.message


@pytest.mark.parametrize("link", ["transition", "then"])
def test_a_chain_as_long_as_the_cap_loads_with_one_tree_and_walks_to_its_end(
        tmp_path: Path, link: str) -> None:
    """A chain of 5,000 modes loaded in 55 s; one of MAX_MODES builds its one tree once."""
    write_project(tmp_path, {"patrol": "R"})
    count = caps.MAX_MODES
    lines = ['project = "mission.b3.json"', 'initial = "m0"']
    for i in range(count):
        lines += [f"[modes.m{i}]", 'tree = "patrol"']
        if link == "then" and i + 1 < count:
            lines += ["max_time = 1.0", f'then = "m{i + 1}"']
        elif i + 1 < count:
            lines += [f'[[transitions]]\nfrom = "m{i}"\nto = "m{i + 1}"\nevent = "next"']
    clock = ManualClock()
    m = load_machine(write_modes(tmp_path, "\n".join(lines) + "\n"), registry=registry(),
                     clock=clock, blackboard=Blackboard({"events": []}))
    assert len({id(tree) for tree in m.trees.values()}) == 1
    assert m.spec.reachable() == set(m.spec.modes)
    for _ in range(count - 1):
        if link == "then":
            m.tick()
            clock.advance(1.0)
        else:
            assert m.fire_event("next").accepted
    m.tick()
    assert m.mode == f"m{count - 1}"


def test_a_gap_in_a_long_chain_leaves_the_modes_after_it_unreachable(tmp_path: Path) -> None:
    write_project(tmp_path, {"patrol": "R"})
    lines = ['project = "mission.b3.json"', 'initial = "m0"']
    for i in range(200):
        lines += [f"[modes.m{i}]", 'tree = "patrol"']
        if i + 1 < 200 and i != 150:
            lines += [f'[[transitions]]\nfrom = "m{i}"\nto = "m{i + 1}"\nevent = "next"']
    found = refused(write_modes(tmp_path, "\n".join(lines) + "\n"))
    assert [p.message.split("'")[1] for p in found] == [f"m{i}" for i in range(151, 200)]


def test_problems_past_the_cap_are_counted_on_one_line(tmp_path: Path) -> None:
    write_project(tmp_path, {"patrol": "R"})
    extra = caps.MAX_PROBLEMS + 50
    text = modes_text({"a": "patrol"}, project='"mission.b3.json"') + "".join(
        f"key{i} = 1\n" for i in range(extra))
    found = refused(write_modes(tmp_path, text))
    assert len(found) == caps.MAX_PROBLEMS + 1
    assert found[-1].message.startswith("and 50 more problems from this line on")
    assert found[-1].line == line_of(text, f"key{caps.MAX_PROBLEMS} =")


def test_a_mode_file_past_its_text_cap_is_refused_with_the_line(tmp_path: Path) -> None:
    write_project(tmp_path, {"patrol": "R"})
    text = modes_text({"a": "patrol"}, project='"mission.b3.json"')
    text += f'description = "{"x" * caps.MAX_TEXT_BYTES}"\n'
    problem, = refused(write_modes(tmp_path, text))
    assert f"more than {caps.MAX_TEXT_BYTES:,} bytes" in problem.message
    assert problem.line == len(text.splitlines())


def test_a_v1_file_and_its_subtree_count_once_against_the_budget(tmp_path: Path) -> None:
    """behavior3editor 1.x: a tree file with a subtree file, named by two modes."""
    leaf = {"id": "1", "name": "Sequence",
            "children": [{"id": str(i), "name": "Succeeder"} for i in range(2, 42)]}
    (tmp_path / "leaf.json").write_text(json.dumps({"version": "1.8.2", "name": "leaf",
                                                    "root": leaf}))
    (tmp_path / "main.json").write_text(json.dumps({
        "version": "1.8.2", "name": "main", "root": {"id": "1", "name": "Sequence", "children": [
            {"id": "2", "name": "Sequence", "path": "leaf.json"},
            {"id": "3", "name": "Sequence", "path": "leaf.json"}]}}))
    text = modes_text({"a": "main", "b": "main"}, key="files", project='["main.json"]')
    path = write_modes(tmp_path, text)
    m = load_machine(path, registry=registry(), clock=ManualClock(), max_nodes=90)
    assert m.trees["a"] is m.trees["b"]
    problem, = refused(path, max_nodes=len(m.trees["a"]) - 1)
    assert "mode 'a'" in problem.message and problem.line == line_of(text, "[modes.a]")


def test_the_documented_cap_errors_are_what_the_loader_says(tmp_path: Path) -> None:
    shown = [line for line in doc_blocks("text")[1].splitlines() if line.strip()]
    write_project(tmp_path, {"patrol": "R"})
    many = modes_text({f"m{i}": "patrol" for i in range(3000)}, project='"mission.b3.json"')
    with pytest.raises(ModeFileError) as caught:
        parse_mode_file(many, "mission.modes.toml", tmp_path)
    assert str(caught.value.problems[0]) == shown[0]
    (tmp_path / "wide.b3.json").write_text(project_json([wide("one", 60), wide("two", 60)]))
    limits = mode_file_limits("mission.modes.toml", max_nodes=100)
    with pytest.raises(ModeFileError) as caught:
        parse_mode_file(modes_text({"a": "one", "b": "one", "c": "two"}), "mission.modes.toml",
                        tmp_path, limits=limits)
    assert [str(problem) for problem in caught.value.problems] == [shown[1]]
