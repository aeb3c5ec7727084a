"""Mode files fuzzed: every mutation of a good file loads, or fails with located problems.

A valid mode file is mutated as text (lines dropped, doubled, swapped or cut; characters
inserted, among them blocks of modes and transitions past the caps; values replaced by values
of other types, names by unknown or odd names), then read. It must either give a machine that
ticks, or raise ModeFileError whose problems each name the mode file (or a tree file it names)
and a line; never any other exception.

Machines are also drawn whole, under small caps (:mod:`cyborg.modes.caps`): modes naming trees
of several sizes (one made of subtree references), chains and other transitions. Each loads
within its caps — every tree built once, however many modes name it, the trees within the node
budget, every mode reachable that a path reaches — or is refused, located, for the cap it
passes.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from cyborg.bt import Blackboard, ManualClock, load_tree
from cyborg.modes import ModeFileError, build_machine, caps, load_machine, parse_mode_file
from cyborg.modes.spec import MachineSpec
from tests.builders import N, project_json, registry, tree_json
from tests.modes.machines import write_modes, write_project
from tests.modes.test_mode_file import GOOD, TREES

_VALUES = ["1", "-1", "0", "nan", "inf", "1e400", '"x"', '""', "true", "[]", '["normal"]',
           "{}", '{ tree = "patrol" }', '"*"', '"normal"', '"low_battery"', '"demo"',
           '"patrol"', '"battery.percent <"', '"a ? b"', '"\\ud800"', "'''\nx\n'''", "[1, [2]]",
           '"' + "(" * 60 + '"', "99999999999999999999999999",
           '"a\\u0000b"', '["x", "\\u0000"]',
           # tomllib's recursion and digit limits: each a located problem, never its exception
           "[" * 1000 + "]" * 1000, "{a=" * 1000 + "1" + "}" * 1000, "1" + "0" * 5000,
           "1" + "0" * 400, "1." + "0" * 400, '"' + "[" * 1000 + '"']
_FRAGMENTS = ["[", "]", "[[", "=", '"', "'", "#", ".", "\n", "[modes.x]", "[[transitions]]",
              "[modes]", "modes = 3", "transitions = 1", "from", "to = ", "\ud800", "\x00",
              # past the caps: more modes, more transitions, more problems than a file may have
              "\n" + "".join(f'[modes.z{i}]\ntree = "patrol"\n' for i in range(300)),
              "\n" + '[[transitions]]\nfrom = "normal"\nto = "demo"\nevent = "e"\n' * 1100,
              "\n" + "".join(f"k{i} = 1\n" for i in range(150))]
_MUTATIONS = st.one_of(
    st.tuples(st.just("drop"), st.integers(0, 200)),
    st.tuples(st.just("double"), st.integers(0, 200)),
    st.tuples(st.just("swap"), st.integers(0, 200), st.integers(0, 200)),
    st.tuples(st.just("value"), st.integers(0, 200), st.sampled_from(_VALUES)),
    st.tuples(st.just("insert"), st.integers(0, 5000), st.sampled_from(_FRAGMENTS)),
    st.tuples(st.just("cut"), st.integers(0, 5000)),
)


def mutate(text: str, mutations: list[tuple[object, ...]]) -> str:
    for mutation in mutations:
        lines = text.splitlines()
        if not lines:
            return text
        kind = mutation[0]
        index = int(str(mutation[1])) % len(lines)
        if kind == "drop":
            del lines[index]
        elif kind == "double":
            lines.insert(index, lines[index])
        elif kind == "swap":
            other = int(str(mutation[2])) % len(lines)
            lines[index], lines[other] = lines[other], lines[index]
        elif kind == "value":
            key = lines[index].split("=", 1)[0]
            lines[index] = f"{key}= {mutation[2]}" if "=" in lines[index] else str(mutation[2])
        elif kind == "insert":
            position = int(str(mutation[1])) % (len(text) + 1)
            text = text[:position] + str(mutation[2]) + text[position:]
            continue
        else:
            text = text[:int(str(mutation[1])) % (len(text) + 1)]
            continue
        text = "\n".join(lines) + "\n"
    return text


@pytest.fixture(scope="module")
def folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("fuzz")
    write_project(path, TREES)
    return path


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(mutations=st.lists(_MUTATIONS, min_size=1, max_size=4))
def test_mutated_mode_files_load_or_fail_with_located_problems(
        folder: Path, mutations: list[tuple[object, ...]]) -> None:
    text = mutate(GOOD, mutations)
    source = str(folder / "fuzzed.modes.toml")
    try:
        spec = parse_mode_file(text, source, folder)
        machine = build_machine(spec, registry=registry(), clock=ManualClock(),
                                blackboard=Blackboard({"events": []}))
    except ModeFileError as exc:
        ours = [problem for problem in exc.problems if problem.source == source]
        assert ours, "no problem names the mode file"
        for problem in ours:
            assert problem.line is not None, str(problem)
        for problem in exc.problems:  # the others are a tree file's (one the mode file named)
            assert problem.source.startswith(str(folder)), str(problem)
            str(problem).encode("utf-8")  # printable, even with a lone surrogate in the file
        return
    machine.tick()
    assert machine.mode in spec.modes
    machine.halt()


_SIZES = {"tiny": 3, "middle": 30, "large": 60}
"""The wide trees of the shapes' project, by id: a Sequence over Succeeders, so many nodes."""
_SHAPE_CAPS = {"MAX_MODES": 6, "MAX_TRANSITIONS": 8}
_LINK = st.tuples(st.integers(0, 7), st.integers(0, 7),
                  st.sampled_from(["event", "on_request", "when", "any"]))
_SHAPES = st.fixed_dictionaries({
    "trees": st.lists(st.sampled_from([*_SIZES, "doubled"]), min_size=1, max_size=8),
    "chain": st.sampled_from(["none", "transitions", "then"]),
    "links": st.lists(_LINK, max_size=10),
    "budget": st.integers(1, 260),
})


@pytest.fixture(scope="module")
def shapes(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, int]]:
    """A project of wide trees and one of two references to 'middle'; instances by tree."""
    path = tmp_path_factory.mktemp("shapes")
    trees = [tree_json(N("Sequence", *[N("Succeeder") for _ in range(size - 1)]),
                       tree_id=tree, title=tree) for tree, size in _SIZES.items()]
    trees.append(tree_json(N("Sequence", N("middle"), N("middle")), tree_id="doubled",
                           title="doubled"))
    (path / "shapes.b3.json").write_text(project_json(trees))
    instances = {tree["id"]: len(load_tree(path / "shapes.b3.json", tree=tree["id"],
                                           registry=registry())) for tree in trees}
    return path, instances


def shape_text(shape: dict[str, object]) -> str:
    """The mode file of a drawn shape: mode i runs the i-th tree drawn."""
    trees = list(shape["trees"])  # type: ignore[call-overload]
    lines = ['project = "shapes.b3.json"', 'initial = "m0"']
    links: list[tuple[int, int, str]] = list(shape["links"])  # type: ignore[call-overload]
    for index, tree in enumerate(trees):
        lines += [f"[modes.m{index}]", f'tree = "{tree}"']
        if shape["chain"] == "then" and index + 1 < len(trees):
            lines += ["max_time = 1.0", f'then = "m{index + 1}"']
        elif shape["chain"] == "transitions" and index + 1 < len(trees):
            links.append((index, index + 1, "event"))
    count = len(trees)
    for number, (source, step, trigger) in enumerate(links):
        source %= count
        target = (source + 1 + step % max(count - 1, 1)) % count  # another mode, if any
        origin = '"*"' if trigger == "any" else f'"m{source}"'
        how = {"event": f'event = "e{number}"', "on_request": "on_request = true",
               "when": f"when = \"x == {number}\"", "any": f'event = "e{number}"'}[trigger]
        lines += ["[[transitions]]", f"from = {origin}", f'to = "m{target}"', how]
    return "\n".join(lines) + "\n"


def naive_reachable(spec: MachineSpec) -> set[str]:
    """The modes a path reaches, each mode tried against every transition (the definition)."""
    seen, frontier = {spec.initial}, [spec.initial]
    while frontier:
        mode = frontier.pop()
        targets = [t.target for t in spec.transitions if t.leaves(mode)]
        then = spec.modes[mode].then
        if then is not None:
            targets.append(then)
        for target in targets:
            if target not in seen:
                seen.add(target)
                frontier.append(target)
    return seen


@settings(max_examples=120, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(shape=_SHAPES)
def test_drawn_machines_load_within_their_caps_or_are_refused_for_the_cap_they_pass(
        shapes: tuple[Path, dict[str, int]], shape: dict[str, object]) -> None:
    folder, instances = shapes
    text = shape_text(shape)
    trees: list[str] = list(shape["trees"])  # type: ignore[call-overload]
    budget = int(str(shape["budget"]))
    needed = sum(instances[tree] for tree in set(trees))
    transitions = text.count("[[transitions]]")
    path = write_modes(folder, text, "shape.modes.toml")
    with pytest.MonkeyPatch.context() as patch:
        for name, value in _SHAPE_CAPS.items():
            patch.setattr(caps, name, value)
        try:
            machine = load_machine(path, registry=registry(), clock=ManualClock(),
                                   max_nodes=budget)
        except ModeFileError as exc:
            ours = [p for p in exc.problems if p.source == str(path)]
            assert ours and all(p.line is not None for p in ours)
            said = " ".join(p.message for p in ours)
            if len(trees) > _SHAPE_CAPS["MAX_MODES"]:
                event("refused: modes")
                assert "modes, more than the 6" in said
            elif transitions > _SHAPE_CAPS["MAX_TRANSITIONS"]:
                event("refused: transitions")
                assert "transitions, more than the 8" in said
            elif "node instances" in said:  # alone, and only when the trees need more
                event("refused: nodes")
                assert len(ours) == 1 and needed > budget
                assert f"more than the {budget:,} one mode file may load" in said
            else:  # the file's own mistakes (unreachable modes, repeated transitions)
                event("refused: the file's mistakes")
                assert "cannot be reached" in said or "repeats" in said or "leads back" in said
            return
    assert len(trees) <= _SHAPE_CAPS["MAX_MODES"] and transitions <= _SHAPE_CAPS[
        "MAX_TRANSITIONS"] and needed <= budget
    event("loaded")
    built = {id(tree): tree for tree in machine.trees.values()}
    assert len(built) == len(set(trees))
    assert sum(len(tree) for tree in built.values()) == needed
    assert machine.spec.reachable() == naive_reachable(machine.spec) == set(machine.spec.modes)
    machine.tick()
    machine.halt()
