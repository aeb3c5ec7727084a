"""The bundled mission `cyborg up` runs: its mode file over its editor project, and the one
blackboard key its conditions read (docs/modes.md, "The bundled mission")."""

from __future__ import annotations

import json
import re
from pathlib import Path

from cyborg.app.cli import build_parser
from cyborg.app.up import CAMPUS_MODES, DATA, up_notes
from cyborg.bt import Blackboard, ManualClock
from cyborg.modes import load_machine, read_mode_file
from cyborg.nav.geometry import Pose2D
from cyborg.robot.perceiving import SeenObject
from cyborg.robot.protocol import ROBOT, Goal, MoveOutcome
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
    assert {"MoveTo", "Charge", "StopSafely", "CallForHelp", "ResumingSequence",
            "ObjectDetected", "ClosestObject", "OncePerObject", "FaceObject", "Say"} <= custom


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


def test_the_patrol_greets_a_person_once_and_drives_on_to_the_goal_it_was_driving_to() -> None:
    places = ["Lecture hall", "Library", "Courtyard", "Cafeteria", "Workshop", "Office"]
    robot = FakeRobot(goals_={name: Goal(name, Pose2D(float(k), 0.0))
                              for k, name in enumerate(places)},
                      pose=Pose2D(0.0, 0.0, 0.0))
    clock = ManualClock()
    machine = load_machine(MODE_FILE, clock=clock,
                           blackboard=Blackboard(resources={ROBOT: robot}))
    assert machine.mode == "normal"
    machine.tick()
    robot.moves[-1].finish(MoveOutcome.SUCCEEDED)  # at the lecture hall
    for _ in range(40):  # its Wait, then on to the library
        clock.advance(0.1)
        machine.tick()
    assert [move.goal for move in robot.moves] == ["Lecture hall", "Library"]
    far = SeenObject(7, "person", 0.9, 3.0, 0.0, 0.0, 0.0, 0.1, 5, 3.0, 0.0)
    robot.seen = [far]  # 3 m ahead: not greeted
    clock.advance(0.1)
    machine.tick()
    assert robot.said == [] and not robot.moves[-1].cancelled
    near = SeenObject(7, "person", 0.9, 1.5, 0.0, 0.0, 0.0, 0.1, 5, 1.5, 0.0)
    robot.seen = [near]  # 1.5 m straight ahead: faced already, greeted
    clock.advance(0.1)
    machine.tick()
    assert robot.said == ["Hello! I am the campus robot."]
    assert robot.moves[-1].cancelled, "the patrol's goal was cancelled for the greeting"
    for _ in range(50):  # the person stays: greeted once, and the patrol goes on
        clock.advance(0.1)
        machine.tick()
    assert robot.said == ["Hello! I am the campus robot."]
    assert [move.goal for move in robot.moves] == ["Lecture hall", "Library", "Library"], \
        "the round resumes at the goal it was driving to"
    assert not robot.moves[-1].cancelled


def test_cyborg_up_says_where_to_hear_the_greetings_when_people_and_the_camera_are_there(
) -> None:
    def notes(*options: str) -> str:
        return "\n".join(up_notes(build_parser().parse_args(["up", *options])))

    assert "`cyborg topic echo /cyborg/say`" in notes()
    assert "/robotN/say" in notes("--robots", "2")
    for options in (["--people", "0"], ["--no-detector"], ["--camera", "real"],
                    ["--tree", "x.b3.json"]):
        assert "/say" not in notes(*options), options
