"""The published JSON Schema agrees with the loader, and docs/modes.md's example is true."""

from __future__ import annotations

import json
import re
import tomllib
from importlib.resources import files
from pathlib import Path
from typing import Any

import jsonschema
import pytest

from cyborg.bt import ManualClock
from cyborg.modes import ModeFileError, load_machine, parse_mode_file
from tests.builders import N, project_json, registry, tree_json
from tests.modes.machines import write_modes, write_project
from tests.modes.test_machine import MISSION
from tests.modes.test_mode_file import GOOD, TREES

DOC = Path(__file__).resolve().parents[2] / "docs" / "modes.md"
DOC_TREES = {"Patrol": "R", "Go charge": "R", "Stop and call": "R", "Demo": "R"}


def schema() -> dict[str, Any]:
    text = files("cyborg.modes").joinpath("modes.schema.json").read_text()
    loaded: dict[str, Any] = json.loads(text)
    jsonschema.Draft202012Validator.check_schema(loaded)
    return loaded


def doc_blocks(language: str) -> list[str]:
    return re.findall(rf"```{language}\n(.*?)```", DOC.read_text(), re.S)


def test_the_examples_are_valid_by_the_schema() -> None:
    validator = jsonschema.Draft202012Validator(schema())
    for text in (GOOD, MISSION, *doc_blocks("toml")):
        errors = [error.message for error in validator.iter_errors(tomllib.loads(text))]
        assert not errors, errors


@pytest.mark.parametrize(("old", "new"), [
    ('tree = "patrol"', 'tre = "patrol"'),                      # unknown key
    ("on_request = true", 'on_request = true\nevent = "go"'),   # two triggers
    ("on_request = true\n", ""),                                # no trigger
    ("then = \"normal\"\n", ""),                                # max_time without then
    ("min_dwell = 2.0", "min_dwell = -2.0"),                    # negative time
    ('to = "demo"', 'to = "demo mode"'),                        # not a name
    ('project = "mission.b3.json"', 'project = ""'),            # no file
])
def test_what_the_schema_refuses_the_loader_refuses(tmp_path: Path, old: str, new: str) -> None:
    text = GOOD.replace(old, new, 1)
    assert text != GOOD
    assert list(jsonschema.Draft202012Validator(schema()).iter_errors(tomllib.loads(text)))
    write_project(tmp_path, TREES)
    with pytest.raises(ModeFileError):
        parse_mode_file(text, "bad.modes.toml", tmp_path)


def test_the_documented_example_loads_and_runs_its_cycle(tmp_path: Path) -> None:
    write_project(tmp_path, {title: "R" for title in DOC_TREES})
    clock = ManualClock()
    machine = load_machine(write_modes(tmp_path, doc_blocks("toml")[0]), registry=registry(),
                           clock=clock)
    machine.globals["battery"] = {"percent": 50}
    machine.tick()
    assert not machine.request("demo", "visitors").accepted  # normal's 2 s are not over
    clock.advance(2.0)
    assert machine.request("demo", "visitors").accepted
    clock.advance(61.0)
    machine.tick()
    assert machine.mode == "normal"
    machine.globals["battery"] = {"percent": 15}
    clock.advance(2.0)
    machine.tick()
    assert machine.mode == "low_battery"
    machine.globals["battery"] = {"percent": 4}
    clock.advance(2.0)
    machine.tick()
    assert machine.mode == "critical" and machine.history[-1].reason == "battery critical"
    clock.advance(2.0)
    assert machine.fire_event("help_arrived").accepted and machine.mode == "normal"


def test_the_documented_errors_are_what_the_loader_says(tmp_path: Path) -> None:
    trees = [tree_json(N("Scripted", script="R"), tree_id=title.lower().replace(" ", "_"),
                       title=title) for title in DOC_TREES]
    (tmp_path / "mission.b3.json").write_text(project_json(trees))
    text = doc_blocks("toml")[0].replace('"Go charge"', '"Go charging"').replace(
        '"battery.percent < 20"', '"battery.percent <"')
    with pytest.raises(ModeFileError) as caught:
        parse_mode_file(text, "mission.modes.toml", tmp_path)
    shown = [line for line in doc_blocks("text")[0].splitlines() if line.strip()]
    said = [str(problem) for problem in caught.value.problems]
    assert len(said) == len(shown) == 2
    assert said[0].startswith(shown[0].removesuffix(", ..."))
    assert said[1] == shown[1]
