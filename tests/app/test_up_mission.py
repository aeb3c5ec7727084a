"""The bundled mission `cyborg up` runs: its mode file over its editor project, and the one
blackboard key its conditions read (docs/modes.md, "The bundled mission")."""

from __future__ import annotations

import json
import re
from pathlib import Path

from cyborg.app.up import CAMPUS_MODES, DATA
from cyborg.bt import Blackboard, ManualClock
from cyborg.modes import load_machine, read_mode_file
from cyborg.robot.interface import ROBOT
from tests.robot.fake_robot import FakeRobot

MODE_FILE = Path(str(DATA.joinpath(CAMPUS_MODES)))


def test_one_tree_per_mode_from_one_editor_project() -> None:
    spec = read_mode_file(MODE_FILE)
    project = json.loads((MODE_FILE.parent / "campus_mission.b3.json").read_text())
    titles = {tree["id"]: tree["title"] for tree in project["trees"]}
    assert {name: titles[mode.tree] for name, mode in spec.modes.items()} == {
        "normal": "Patrol", "low_battery": "Go charge", "critical": "Stop and call",
        "demo": "Demo"}
    assert (project["version"], project["scope"]) == ("0.3.0", "project")
    assert [tree["title"] for tree in project["trees"]] == [
        "Patrol", "Go charge", "Stop and call", "Demo"]
    custom = {node["name"] for node in project["custom_nodes"]}
    assert {"MoveTo", "Charge", "StopSafely", "CallForHelp"} <= custom


def test_every_tree_reads_the_battery_into_the_key_the_conditions_read() -> None:
    spec = read_mode_file(MODE_FILE)
    sources = [condition.source for transition in spec.transitions
               for condition in (transition.when, transition.guard) if condition is not None]
    names = {name for source in sources
             for name in re.findall(r"(?<![.\w])([A-Za-z_]\w*)", source)}
    assert names == {"battery"}, sources
    machine = load_machine(MODE_FILE, clock=ManualClock(),
                           blackboard=Blackboard(resources={ROBOT: FakeRobot()}))
    for mode, tree in machine.trees.items():
        first = tree.root.children[0]  # the tree's Subtree wraps the root Sequence
        services = tree.services
        assert first.name == "Sequence" and services is not None, mode
        watches = [scheduled.service for scheduled in services.of(first)
                   if scheduled.service.name == "BatteryWatch"]
        assert [getattr(service, "key", None) for service in watches] == ["battery"], mode
