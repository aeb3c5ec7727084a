"""Objects seen lately as discs: kept, refreshed, forgotten, and planned around."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cyborg.nav.arnl_map import parse_map
from cyborg.nav.geometry import Pose2D
from cyborg.nav.planner import NO_VALID_PATH, Planner
from cyborg.nav.temporary_obstacles import (
    ObstacleSettings,
    TemporaryObstacles,
    clear_of,
    path_blocked,
)
from tests.small_maps import room_map

LEFT, RIGHT = Pose2D(2.0, 3.0), Pose2D(8.0, 3.0)
KEEP_OUT = ObstacleSettings().keep_out


@pytest.fixture(scope="module")
def planner() -> Planner:
    return Planner(parse_map(room_map([])))


def disc(x: float, y: float, keep_out: float = KEEP_OUT) -> np.ndarray:
    return np.array([[x, y, keep_out]])


def closest_approach(planner: Planner, start: Pose2D, goal: Pose2D, centre: tuple[float, float],
                     discs: np.ndarray) -> float:
    result = planner.plan(start, goal, discs=discs)
    assert result.path is not None, result.reason
    samples = result.path.sample(0.0, result.path.length, 0.02)
    return float(np.hypot(samples[:, 0] - centre[0], samples[:, 1] - centre[1]).min())


def test_a_sighting_is_a_disc_until_it_is_forgotten_and_a_new_sighting_refreshes_it() -> None:
    obstacles = TemporaryObstacles(ObstacleSettings(forget_after=4.0))
    assert obstacles.see("a", 1.0, 2.0, seen_at=10.0)
    assert obstacles.discs(13.9).tolist() == [[1.0, 2.0, KEEP_OUT]]
    assert obstacles.discs(14.1).shape == (0, 3) and len(obstacles) == 0
    obstacles.see("b", 1.0, 2.0, seen_at=20.0)
    obstacles.see("b", 1.5, 2.0, seen_at=23.0)  # seen again, a little further on
    assert obstacles.discs(26.0).tolist() == [[1.5, 2.0, KEEP_OUT]]
    assert obstacles.forget(27.5) == 1 and len(obstacles) == 0


def test_bad_or_older_sightings_change_nothing() -> None:
    obstacles = TemporaryObstacles()
    assert not obstacles.see(1, math.nan, 0.0, seen_at=1.0)
    assert not obstacles.see(1, 0.0, 0.0, seen_at=math.inf)
    assert obstacles.see(1, 0.0, 0.0, seen_at=5.0)
    assert not obstacles.see(1, 9.0, 9.0, seen_at=4.0), "an older message arrived late"
    assert obstacles.discs(5.0)[:, :2].tolist() == [[0.0, 0.0]]
    assert obstacles.see(2, 3.0, 0.0, seen_at=5.0, velocity=(math.nan, 1.0))
    assert obstacles.discs(5.5)[:, :2].tolist() == [[0.0, 0.0], [3.0, 0.0]], \
        "a velocity that is not a number counts as standing still"
    with pytest.raises(ValueError, match="forget_after"):
        ObstacleSettings(forget_after=-1.0)
    with pytest.raises(ValueError, match="object_radius"):
        ObstacleSettings(object_radius=math.nan)


def test_a_moving_object_is_carried_along_its_velocity_for_a_second_at_most() -> None:
    obstacles = TemporaryObstacles(ObstacleSettings(extrapolate=1.0))
    obstacles.see(3, 1.0, 1.0, seen_at=0.0, velocity=(1.0, -0.5))
    assert obstacles.discs(0.5)[0, :2] == pytest.approx([1.5, 0.75])
    assert obstacles.discs(3.0)[0, :2] == pytest.approx([2.0, 0.5])


def test_discs_near_a_point_only() -> None:
    obstacles = TemporaryObstacles()
    obstacles.see(1, 1.0, 0.0, seen_at=0.0)
    obstacles.see(2, 9.0, 0.0, seen_at=0.0)
    assert obstacles.discs(0.0, near=(0.0, 0.0), within=6.0)[:, 0].tolist() == [1.0]


def test_the_planner_keeps_the_robot_clear_of_a_person_in_the_room(planner: Planner) -> None:
    start, goal, person = Pose2D(1.0, 3.0), Pose2D(4.2, 3.0), (2.6, 3.0)
    plain = planner.plan(start, goal)
    around = planner.plan(start, goal, discs=disc(*person))
    assert plain.found and around.found and around.length > plain.length + 0.2
    gap = closest_approach(planner, start, goal, person, disc(*person))
    assert gap >= KEEP_OUT + planner.lethal - planner.grid.resolution
    wider = closest_approach(planner, start, goal, person, disc(*person, keep_out=0.8))
    assert wider >= 0.8 + planner.lethal - planner.grid.resolution, "the clearance is the disc's"


def test_a_person_in_the_door_cuts_the_rooms_apart_without_touching_the_cached_grids(
        planner: Planner) -> None:
    clearance, cost = planner.clearance.copy(), planner.cost.copy()
    blocked = planner.plan(LEFT, RIGHT, discs=disc(5.0, 3.0))
    assert (blocked.found, blocked.code) == (False, NO_VALID_PATH)
    assert planner.plan(LEFT, RIGHT).found, "without the person the door is open"
    np.testing.assert_array_equal(planner.clearance, clearance)
    np.testing.assert_array_equal(planner.cost, cost)
    with_nan = np.vstack([disc(5.0, 3.0), [[math.nan, 3.0, KEEP_OUT]]])
    assert planner.plan(LEFT, RIGHT, discs=with_nan).code == NO_VALID_PATH, \
        "a disc that is not a number is left out, the others still count"


def test_a_person_standing_at_the_goal_or_beside_the_start_never_cuts_it_off(
        planner: Planner) -> None:
    at_goal = planner.plan(LEFT, RIGHT, discs=disc(RIGHT.x, RIGHT.y))
    assert at_goal.path is not None
    assert at_goal.path.goal.x == RIGHT.x and at_goal.path.goal.y == RIGHT.y
    beside = planner.plan(LEFT, RIGHT, discs=disc(LEFT.x + 0.1, LEFT.y - 0.5))
    assert beside.found
    near_goal = (RIGHT.x - 0.6, RIGHT.y)  # the disc shrinks, and still keeps the path off it
    gap = closest_approach(planner, LEFT, RIGHT, near_goal, disc(*near_goal))
    assert gap >= 0.6 - planner.grid.resolution


def test_clear_of_shrinks_only_the_discs_that_hold_a_point() -> None:
    discs = np.array([[0.0, 0.0, 0.4], [5.0, 0.0, 0.4]])
    shrunk = clear_of(discs, [(0.5, 0.0)], lethal=0.4, spare=0.1)
    assert shrunk[:, 2] == pytest.approx([0.0, 0.4])
    assert discs[0, 2] == 0.4, "the discs given are left as they were"


def test_a_path_is_blocked_only_when_it_runs_into_a_lethal_zone_beyond_the_hysteresis() -> None:
    path = np.column_stack([np.linspace(0.0, 5.0, 51), np.zeros(51)])
    lethal, hysteresis = 0.4, 0.1
    assert path_blocked(disc(2.0, 0.5), path, lethal, hysteresis)
    assert not path_blocked(disc(2.0, KEEP_OUT + lethal - 0.05), path, lethal, hysteresis), \
        "a path planned around the disc stays clear when the person shifts a little"
    assert not path_blocked(np.zeros((0, 3)), path, lethal, hysteresis)
