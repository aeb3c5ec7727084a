"""`cyborg up --robots N`: N simulated robots on one map, each in its own namespace with its
own tree runner, one monitor for all of them; a clear error for a count that cannot be."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from cyborg.app.cli import build_parser
from cyborg.app.errors import CommandError
from cyborg.app.launch import Launch
from cyborg.app.up import FLEET_BATTERY_STEP, up_description, up_notes
from cyborg.bus import BusConfig, Context
from cyborg.bus.component import LaunchError
from cyborg.bus.wire import EntityKind
from cyborg.runner.component import RunningTree
from cyborg.sim.component import RunningFleet
from tests.running_system import wait_until

ROBOTS = ["/robot1", "/robot2", "/robot3"]


def _description(*words: str) -> dict[str, list[tuple[str, str, dict[str, object]]]]:
    args = build_parser().parse_args(["up", *words])
    kinds: dict[str, list[tuple[str, str, dict[str, object]]]] = {}
    for spec in up_description(args).nodes:
        kinds.setdefault(spec.kind, []).append((spec.name, spec.namespace, spec.parameters))
    return kinds


def test_three_robots_are_one_fleet_three_tree_runners_and_one_monitor() -> None:
    kinds = _description("--robots", "3", "--no-detector")
    [(_, fleet_namespace, fleet)] = kinds["simulator"]
    assert fleet_namespace == "/" and fleet["robots"] == 3, "one simulator, three robots"
    assert fleet["battery_step"] == FLEET_BATTERY_STEP, "they take turns at the charger"
    runners = [(namespace, parameters["robot_namespace"])
               for _, namespace, parameters in kinds["tree_runner"]]
    assert runners == [(f"{robot}/bt", robot) for robot in ROBOTS]
    [(_, _, monitor)] = kinds["monitor"]
    assert monitor["trees"] == [f"{robot}/bt" for robot in ROBOTS]


def test_the_first_lines_say_how_full_each_robot_starts() -> None:
    notes = up_notes(build_parser().parse_args(["up", "--robots", "4", "--battery", "60"]))
    assert notes[1] == ("robots       4 (--robots), each with its tree; batteries at 60, 78, "
                        "96, 100 %, so they take turns at the charger")


def test_one_robot_is_as_before() -> None:
    kinds = _description("--no-detector")
    [(_, namespace, simulator)] = kinds["simulator"]
    assert namespace == "/cyborg" and "robots" not in simulator
    assert [(n, p["robot_namespace"]) for _, n, p in kinds["tree_runner"]] == [
        ("/cyborg/bt", "/cyborg")]


def test_the_detector_serves_the_first_robot() -> None:
    kinds = _description("--robots", "2", "--camera", "real")
    vision = kinds["detector"] + kinds["camera"]
    assert vision and all(namespace.startswith("/robot1/") for _, namespace, _ in vision)


@pytest.mark.parametrize(("words", "said"), [
    (["--robots", "0"], "--robots must be from 1 to 16, not 0"),
    (["--robots", "17"], "--robots must be from 1 to 16, not 17"),
    (["--robots", "2", "--namespace", "/lab"],
     "--namespace names one robot; with --robots 2 the robots are /robot1 ... /robot2"),
])
def test_a_count_that_cannot_be_is_a_clear_error(words: list[str], said: str) -> None:
    with pytest.raises(CommandError) as raised:
        up_description(build_parser().parse_args(["up", *words]))
    assert str(raised.value) == said


def test_more_robots_than_the_map_has_room_for_is_a_clear_error(shared: Path) -> None:
    args = build_parser().parse_args(["up", "--robots", "14", "--map",
                                      str(shared / "maps" / "AMROffice.map"), "--no-monitor",
                                      "--no-detector"])
    with Context(BusConfig.isolated()) as context:
        launch = Launch(up_description(args), context)
        with pytest.raises(LaunchError) as raised:
            launch.start()
    assert str(raised.value) == (
        f"simulator (--robots): robots: {shared / 'maps' / 'AMROffice.map'} has room for 12 "
        "robots (1.5 m apart, off goals and docks, where the first can drive), not 14")
    assert launch.running == [], "nothing was left running"


@pytest.mark.heavy
def test_cyborg_up_with_three_robots_drives_each_with_its_own_tree() -> None:
    args = build_parser().parse_args(["up", "--robots", "3", "--no-monitor", "--no-detector",
                                      "--speed", "10"])
    with Context(BusConfig.isolated()) as context:
        launch = Launch(up_description(args), context)
        launch.start()
        try:
            [fleet] = [item for item in launch.running if isinstance(item, RunningFleet)]
            runners = [item for item in launch.running if isinstance(item, RunningTree)]
            assert [node.namespace for node in fleet.nodes] == ROBOTS
            assert [item.runner.node.namespace for item in runners] == [
                f"{robot}/bt" for robot in ROBOTS]
            graph = context.graph
            wait_until(lambda: all(graph.count(f"{robot}/pose", EntityKind.PUBLISHER) == 1
                                   for robot in ROBOTS), 20, "each robot's pose on the bus")
            assert graph.count("/clock", EntityKind.PUBLISHER) == 1
            sims = fleet.fleet.simulators
            with fleet.loop.lock:
                starts = [sim.pose for sim in sims]
                charges = [sim.battery.charge_percent for sim in sims]
            assert charges == pytest.approx([33.0, 51.0, 69.0], abs=0.5), "each next one fuller"

            def all_moved() -> bool:
                with fleet.loop.lock:
                    return all(math.hypot(sim.pose.x - start.x, sim.pose.y - start.y) > 0.5
                               for sim, start in zip(sims, starts, strict=True))
            wait_until(all_moved, 90, "every robot to drive off on its own patrol")
        finally:
            launch.stop()
