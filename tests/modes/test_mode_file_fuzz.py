"""Mode files fuzzed: every mutation of a good file loads, or fails with located problems.

A valid mode file is mutated as text (lines dropped, doubled, swapped or cut; characters
inserted; values replaced by values of other types, names by unknown or odd names), then read.
It must either give a machine that ticks, or raise ModeFileError whose problems each name the
mode file (or a tree file it names) and a line; never any other exception.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cyborg.bt import Blackboard, ManualClock
from cyborg.modes import ModeFileError, build_machine, parse_mode_file
from tests.builders import registry
from tests.modes.machines import write_project
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
              "[modes]", "modes = 3", "transitions = 1", "from", "to = ", "\ud800", "\x00"]
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
