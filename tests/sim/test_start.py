"""Where the simulated robot starts: the given pose or goal, the map's home, its dock, or else
a free point near the middle of the map, with a message saying which and why."""

from __future__ import annotations

import logging
import math
from pathlib import Path

import pytest

from cyborg.nav.arnl_map import parse_map, read_map
from cyborg.nav.geometry import Pose2D
from cyborg.nav.planner import Planner, PlannerSettings
from cyborg.sim.simulator import Simulator
from tests.small_maps import room_map


def assert_free_with_room_to_turn(sim: Simulator) -> None:
    """The start is a legal planning start and the body can turn on the spot there."""
    pose, planner = sim.pose, sim.planner
    assert planner.check(pose, "start") is None
    clearance = planner.grid.clearance_at(planner.clearance, pose.x, pose.y)
    assert clearance >= planner.footprint.circumscribed_radius + 0.05
    for heading in range(0, 360, 15):
        assert not sim.base.collides(Pose2D(pose.x, pose.y, math.radians(heading)))


def start_messages(caplog: pytest.LogCaptureFixture) -> list[str]:
    return [record.getMessage() for record in caplog.records if record.name == "cyborg.sim"]


def test_without_home_or_dock_the_robot_starts_clear_of_a_wall_through_the_centre(
        caplog: pytest.LogCaptureFixture) -> None:
    # The room's wall at x = 5 m and a new one at y = 3 m cross at the map's centre (5, 3).
    arnl_map = parse_map(room_map([], lines=[(0, 3000, 10000, 3000)]), "crossed.map")
    with caplog.at_level(logging.INFO, "cyborg.sim"):
        sim = Simulator(arnl_map)
    assert_free_with_room_to_turn(sim)
    assert math.hypot(sim.pose.x - 5.0, sim.pose.y - 3.0) <= 1.0
    (message,) = start_messages(caplog)
    assert "crossed.map has no home or dock" in message
    assert "nearest the centre (5.00, 3.00)" in message
    assert f"({sim.pose.x:.2f}, {sim.pose.y:.2f})" in message
    assert caplog.records[-1].levelno == logging.WARNING
    assert sim.start_choice.pose == sim.pose and sim.start_choice.reason == message


def test_the_free_point_is_inside_the_walls_not_outside_them() -> None:
    """The centre of an L-shaped building's extent lies outside it, in the open."""
    outline = [(0, 0), (10000, 0), (10000, 4000), (4000, 4000), (4000, 10000), (0, 10000)]
    walls = [(*outline[i], *outline[(i + 1) % len(outline)]) for i in range(len(outline))]
    text = "2D-Map\nLINES\n" + "".join(" ".join(map(str, wall)) + "\n" for wall in walls)
    sim = Simulator(parse_map(text + "DATA\n"))
    assert_free_with_room_to_turn(sim)
    assert sim.pose.x < 4.0 or sim.pose.y < 4.0
    assert math.hypot(sim.pose.x - 5.0, sim.pose.y - 5.0) <= 2.0


def test_a_room_too_small_for_the_robot_is_said_so(caplog: pytest.LogCaptureFixture) -> None:
    box = "2D-Map\nLINES\n0 0 500 0\n500 0 500 500\n500 500 0 500\n0 500 0 0\nDATA\n"
    arnl_map = parse_map(box, "box.map")
    with caplog.at_level(logging.INFO, "cyborg.sim"):
        sim = Simulator(arnl_map)  # a 0.5 m box: the robot stands outside it
        assert_free_with_room_to_turn(sim)
        assert "outside the map's walls" in start_messages(caplog)[-1]
        fat = Planner(arnl_map, settings=PlannerSettings(padding=5.0))  # clear nowhere
        sim.load_map(arnl_map, planner=fat)
    assert "no point of it is 5.50 m from walls" in start_messages(caplog)[-1]
    assert "roomiest point" in start_messages(caplog)[-1]
    assert fat.grid.clearance_at(fat.clearance, sim.pose.x, sim.pose.y) == fat.clearance.max()


def test_an_unknown_start_name_changes_nothing() -> None:
    sim = Simulator(parse_map(room_map(['Goal 2000 3000 0 "" ICON "a"'])), start="a")
    other = parse_map(room_map([]), "other.map")
    with pytest.raises(KeyError, match="no goal named 'b'"):
        sim.load_map(other, start="b")
    assert sim.map.source == "<map>" and sim.pose == Pose2D(2.0, 3.0)


def test_a_home_area_gives_its_free_point_nearest_its_middle(
        caplog: pytest.LogCaptureFixture) -> None:
    cairns = ['RobotHome 0 0 0 "" ICON "" 6000 1000 9000 5000', 'Goal 2000 3000 0 "" ICON "a"']
    with caplog.at_level(logging.INFO, "cyborg.sim"):
        sim = Simulator(parse_map(room_map(cairns, lines=[(6000, 3000, 9000, 3000)])))
    assert_free_with_room_to_turn(sim)
    assert 6.0 <= sim.pose.x <= 9.0 and 1.0 <= sim.pose.y <= 5.0
    assert math.hypot(sim.pose.x - 7.5, sim.pose.y - 3.0) <= 1.0
    assert "home area" in start_messages(caplog)[-1]


@pytest.mark.parametrize(("cairn", "pose", "words"), [
    ('RobotHome 2000 1000 90 "" ICON "Home"', (2.0, 1.0, 90), "the map's home"),
    ('Dock 8000 1000 -90 "" ICON "Charger"', (8.0, 1.0, -90), "dock 'Charger'"),
])
def test_a_home_or_else_a_dock_is_where_the_robot_starts(
        caplog: pytest.LogCaptureFixture, cairn: str, pose: tuple[float, float, float],
        words: str) -> None:
    with caplog.at_level(logging.INFO, "cyborg.sim"):
        sim = Simulator(parse_map(room_map([cairn, 'Goal 3000 3000 0 "" ICON "g"'])))
    assert sim.pose == Pose2D(pose[0], pose[1], math.radians(pose[2]))
    assert words in start_messages(caplog)[-1]


def test_columbia_without_its_home_starts_free_near_the_centre(
        shared: Path, tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    original = (shared / "maps" / "columbia.map").read_bytes()
    homeless = tmp_path / "columbia.map"
    homeless.write_bytes(b"".join(line for line in original.splitlines(keepends=True)
                                  if not line.startswith(b"Cairn: RobotHome")))
    arnl_map = read_map(homeless)
    assert not arnl_map.homes() and not arnl_map.docks() and arnl_map.goals()
    with caplog.at_level(logging.INFO, "cyborg.sim"):
        sim = Simulator(arnl_map)
    assert_free_with_room_to_turn(sim)
    min_x, min_y, max_x, max_y = arnl_map.bounds()
    assert math.hypot(sim.pose.x - (min_x + max_x) / 2, sim.pose.y - (min_y + max_y) / 2) < 1.0
    assert "has no home or dock" in start_messages(caplog)[-1]


def test_a_named_home_can_be_given_as_the_start(shared: Path) -> None:
    triangle = read_map(shared / "maps" / "triangle.map")
    sim = Simulator(triangle, start="Home")
    assert sim.pose == Pose2D(5.09, 3.58, math.radians(54))
    assert "RobotHome 'Home'" in sim.start_choice.reason
