"""Poses, paths and planning on real and small maps."""

from __future__ import annotations

import math
import threading
from pathlib import Path as FilePath

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cyborg.bus import MessageTypes
from cyborg.nav.arnl_map import parse_map, read_map
from cyborg.nav.geometry import Path, Pose2D, Quaternion
from cyborg.nav.planner import GOAL_OCCUPIED, NO_VALID_PATH, Planner
from tests.small_maps import room_map

LEFT, RIGHT = Pose2D(2.0, 3.0), Pose2D(8.0, 3.0)


@given(st.floats(-math.pi, math.pi - 1e-9))
def test_quaternion_yaw_round_trip(yaw: float) -> None:
    assert Quaternion.from_yaw(yaw).yaw == pytest.approx(yaw, abs=1e-9)


def test_path_length_progress_and_messages() -> None:
    path = Path([(0, 0), (3, 0), (3, 4)], final_heading=1.0)
    assert path.length == 7.0
    assert path.project(1.0, 0.5) == (1.0, 0.5)
    assert path.remaining_from(3.2, 2.0) == pytest.approx(2.0)
    assert path.point_at(5.0) == (3.0, 2.0) and path.point_at(99) == (3.0, 4.0)
    rest = path.advance_to(2.0, -0.1)
    assert rest.length == pytest.approx(5.0) and rest.points[0].tolist() == [2.0, 0.0]
    assert len(path.sample(0.0, 7.0, 1.0)) == 7
    message = path.to_message()
    assert type(message) is MessageTypes().message_class("nav_msgs/msg/Path")  # the bus's own
    back = Path.from_message(message)
    np.testing.assert_allclose(back.points, path.points)
    assert back.final_heading == pytest.approx(1.0)
    assert Pose2D.from_message(Pose2D(1, 2, 0.5).to_pose().to_message()) == pytest.approx(
        Pose2D(1, 2, 0.5))
    with pytest.raises(ValueError, match="at least one point"):
        Path([])


@settings(deadline=None)
@given(st.lists(st.tuples(st.floats(-5, 5), st.floats(-5, 5)), min_size=1, max_size=6),
       st.floats(-1, 12), st.floats(-1, 12), st.sampled_from([0.05, 0.1, 0.2, 1.0]))
def test_points_sampled_along_a_path_lie_where_interpolation_puts_them(
        points: list[tuple[float, float]], start: float, stop: float, step: float) -> None:
    """Every ``step`` m from ``start`` up to ``stop`` (clamped to the path), repeated corners
    and all: as ``np.interp`` over the path's lengths gives them."""
    path = Path(points)
    distances = np.arange(max(start, 0.0), min(stop, path.length), step)
    lengths = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(path.points, axis=0).T))])
    expected = np.column_stack([np.interp(distances, lengths, path.points[:, 0]),
                                np.interp(distances, lengths, path.points[:, 1])])
    found = path.sample(start, stop, step)
    assert found.shape == expected.shape
    np.testing.assert_allclose(found, expected, atol=1e-9)


def test_path_through_the_door_keeps_clear_of_walls() -> None:
    planner = Planner(parse_map(room_map([])))
    result = planner.plan(LEFT, RIGHT, use_heading=True)
    assert result.found and result.code == "NONE"
    assert 6.0 <= result.length < 6.6
    assert result.path is not None and result.path.goal.theta == 0.0
    for x, y in result.path.sample(0.0, result.path.length, 0.02):
        assert planner.grid.clearance_at(planner.wall_clearance, x, y) >= planner.tight


def test_goals_inside_walls_forbidden_zones_or_cut_off_have_no_path() -> None:
    arnl_map = parse_map(room_map(
        ['ForbiddenArea 0 0 0 "" ICON "" 7000 500 9500 1500',
         'ForbiddenLine 0 0 0 "" ICON "" 5000 2400 5000 3600'],  # closes the door
        lines=[(1000, 1000, 2000, 1000), (2000, 1000, 2000, 2000), (2000, 2000, 1000, 2000),
               (1000, 2000, 1000, 1000)]))  # a closed 1 m box in the left room
    planner = Planner(arnl_map)
    wall = planner.plan(LEFT, Pose2D(5.0, 1.0))
    assert (wall.found, wall.code, wall.length) == (False, GOAL_OCCUPIED, math.inf)
    assert "inside a wall" in wall.reason
    forbidden = planner.plan(LEFT, Pose2D(8.0, 1.0))
    assert forbidden.code == GOAL_OCCUPIED and "forbidden" in forbidden.reason
    boxed = planner.plan(LEFT, Pose2D(1.5, 1.5))
    assert boxed.code == NO_VALID_PATH
    beyond_line = planner.plan(LEFT, RIGHT)
    assert beyond_line.code == NO_VALID_PATH


def test_rotated_forbidden_area_blocks_where_it_lies() -> None:
    # raw corners off the map; rotated by 90 degrees they cover the door (x 4.5..5.5, y 1..5)
    arnl_map = parse_map(room_map(['ForbiddenArea 0 0 90 "" ICON "" 1000 -5500 5000 -4500']))
    assert Planner(arnl_map).plan(LEFT, RIGHT).code == NO_VALID_PATH
    assert Planner(parse_map(room_map([]))).plan(LEFT, RIGHT).found


def test_columbia_impossible_and_forbidden_goals(shared: FilePath) -> None:
    arnl_map = read_map(shared / "maps" / "columbia.map")
    planner = Planner(arnl_map)
    start = Pose2D(arnl_map.homes()[0].x, arnl_map.homes()[0].y)
    results = {item.name: planner.plan(start, Pose2D(item.x, item.y)) for item in arnl_map.goals()}
    assert results["Impossible Goal"].length == math.inf
    assert results["Inside Forbidden Area"].code == GOAL_OCCUPIED
    reachable = {name for name, result in results.items() if result.found}
    assert reachable == {item.name for item in arnl_map.goals()} - {
        "Impossible Goal", "Inside Forbidden Area"}
    for name in reachable:
        item = arnl_map.goal(name)
        assert results[name].length >= math.dist((start.x, start.y), (item.x, item.y)) - 1e-6
    for x, y in results["Hallway 2"].path.sample(0.0, results["Hallway 2"].length, 0.02):  # type: ignore[union-attr]
        row, column = planner.grid.cell(x, y)
        assert not planner.grid.forbidden[row, column]


def test_a_goal_covered_by_sensed_obstacles_is_occupied_and_a_free_one_is_planned() -> None:
    planner = Planner(parse_map(room_map([])))
    ring = np.array([(RIGHT.x + 0.1 * math.cos(a), RIGHT.y + 0.1 * math.sin(a))
                     for a in np.linspace(0, 2 * math.pi, 16, endpoint=False)])
    covered = planner.plan(LEFT, RIGHT, obstacles=ring)
    assert (covered.found, covered.code) == (False, GOAL_OCCUPIED)
    assert "(8.00, 3.00)" in covered.reason and "obstacle" in covered.reason
    aside = planner.plan(LEFT, RIGHT, obstacles=ring + np.array([0.0, 2.0]))  # 2 m off the goal
    assert aside.found and aside.code == "NONE"


def test_a_way_near_by_is_found_in_a_small_box_and_a_closed_door_has_none() -> None:
    planner = Planner(parse_map(room_map([])))
    before, after = Pose2D(4.0, 3.0), Pose2D(6.0, 3.0)
    nothing = np.zeros((0, 2))
    assert planner.passable_near(before, after, nothing, margin=1.0)
    door = np.column_stack([np.full(13, 5.0), np.linspace(2.4, 3.6, 13)])  # someone in it
    assert not planner.passable_near(before, after, door, margin=1.0)
    aside = door + np.array([0.0, 1.5])  # by the wall beside the door: the door is free
    assert planner.passable_near(before, after, aside, margin=1.0)
    # the room's far side is only reached round a wall the small box leaves out
    assert not planner.passable_near(Pose2D(4.0, 1.0), Pose2D(6.0, 1.0), nothing, margin=0.5)
    assert planner.passable_near(Pose2D(4.0, 1.0), Pose2D(6.0, 1.0), nothing, margin=2.5)


def test_plans_with_obstacles_leave_later_plans_and_other_threads_as_they_were() -> None:
    """Plans past people and sensed points, from two threads at once, then plans without: each
    as a planner of its own gives it."""
    arnl_map = parse_map(room_map([]))
    shared, fresh = Planner(arnl_map), Planner(arnl_map)
    people = np.array([(5.0, 3.3, 0.3)])
    points = np.array([(5.0, 2.5), (5.0, 2.55)])
    asks = [dict(discs=people), dict(obstacles=points), {}, dict(discs=people, obstacles=points)]
    expected = [fresh.plan(LEFT, RIGHT, **ask) for ask in asks]  # type: ignore[arg-type]
    found: dict[int, list[float]] = {0: [], 1: []}

    def plan_all(index: int) -> None:
        for _ in range(20):
            for ask in asks:
                found[index].append(shared.plan(LEFT, RIGHT, **ask).length)  # type: ignore[arg-type]

    threads = [threading.Thread(target=plan_all, args=(index,)) for index in (0, 1)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    for lengths in found.values():
        assert lengths == [result.length for result in expected] * 20
    assert shared.plan(LEFT, RIGHT).length == fresh.plan(LEFT, RIGHT).length
