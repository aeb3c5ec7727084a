"""Other robots' bodies as obstacles: the gap between two outlines, beams that hit an outline,
points along it, and the drive that will not push one body into another."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial import ConvexHull

from cyborg.nav.footprint import PIONEER_LX
from cyborg.nav.geometry import Pose2D
from cyborg.sim.bodies import (
    braking_outline,
    braking_poses,
    cast_onto,
    cast_onto_fan,
    grown,
    nearest_gap,
    outline_at,
    outline_points,
    placed,
    polygon_gap,
)
from cyborg.sim.robot import RobotBase

SQUARE = np.array([[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]])


def square(x: float, y: float, theta: float = 0.0) -> np.ndarray:
    return outline_at(SQUARE, Pose2D(x, y, theta))


@pytest.mark.parametrize(("other", "gap"), [
    (square(2.0, 0.0), 1.0),  # side by side
    (square(1.0, 0.0), 0.0),  # touching
    (square(0.8, 0.0), -0.2),  # overlapping by 0.2 m
    (square(2.0, 2.0), math.sqrt(2.0)),  # corner to corner
    (square(0.5 + math.sqrt(0.5) + 0.3, 0.0, math.pi / 4), 0.3),  # a corner towards a side
])
def test_the_gap_between_two_outlines(other: np.ndarray, gap: float) -> None:
    assert polygon_gap(square(0.0, 0.0), other) == pytest.approx(gap, abs=1e-9)
    assert polygon_gap(other, square(0.0, 0.0)) == pytest.approx(gap, abs=1e-9)


def test_the_nearest_of_several_outlines_counts() -> None:
    assert nearest_gap(square(0, 0), [square(5, 0), square(0, 3)]) == pytest.approx(2.0)
    assert nearest_gap(square(0, 0), []) == math.inf


def test_beams_stop_at_the_first_edge_of_an_outline() -> None:
    ranges = np.array([10.0, 10.0, 10.0, 0.5])
    angles = np.array([0.0, math.pi / 2, math.pi, 0.0])
    cast_onto(square(3.0, 0.0), 0.0, 0.0, angles, ranges)
    # straight at it: its near side, 2.5 m; sideways and backwards: missed; a wall nearer stays
    assert ranges.tolist() == pytest.approx([2.5, 10.0, 10.0, 0.5])


@settings(max_examples=100, deadline=None)
@given(st.integers(0, 2**31))
def test_a_laser_fan_is_cut_short_by_an_outline_as_beam_by_beam(seed: int) -> None:
    """A convex outline anywhere, the scanner anywhere (inside it too), a fan of 541 beams
    over 270° starting at any angle: the beams tried within the outline's width end where
    every beam tried alone ends."""
    random = np.random.default_rng(seed)
    middle, radius = random.uniform(-3, 3, 2), random.uniform(0.1, 0.8)
    turns = np.sort(random.uniform(0, 2 * np.pi, 12))
    outline = np.column_stack([middle[0] + radius * np.cos(turns),
                               middle[1] + radius * np.sin(turns)])
    x, y = random.uniform(-3, 3, 2)
    first, increment = random.uniform(-4, 4), math.radians(270) / 540
    alone, fan = np.full(541, 30.0), np.full(541, 30.0)
    cast_onto(outline, x, y, first + np.arange(541) * increment, alone)
    cast_onto_fan(outline, x, y, first, increment, fan)
    assert np.array_equal(alone, fan)


def test_points_along_an_outline_are_close_together_and_on_it() -> None:
    points = outline_points(square(0, 0), spacing=0.05)
    assert len(points) == 4 * 20
    steps = np.hypot(*np.diff(np.vstack([points, points[:1]]), axis=0).T)
    assert steps.max() <= 0.05 + 1e-9
    assert np.allclose(np.abs(points).max(axis=1), 0.5)


def test_the_drive_stops_short_of_another_robot() -> None:
    """A robot driving at another stalls with its bumper pressed, never overlapping it."""
    clearance = np.full((200, 200), 10.0)  # an open field, 10 m x 10 m
    base = RobotBase(clearance, (0.0, 0.0), 0.05, pose=Pose2D(2.0, 5.0, 0.0))
    other = outline_at(PIONEER_LX.polygon(), Pose2D(4.0, 5.0, math.pi / 2))
    base.others = (other,)
    for _ in range(400):  # 8 s at 1 m/s: far past the other robot if nothing stopped it
        base.command(1.0, 0.0, 0.02)
        assert base.robots_gap(base.pose) >= 0.0
    assert base.bumpers.front and base.speed == 0.0
    assert base.robots_gap(base.pose) < 0.05, "it stopped against the other robot"
    base.command(-0.3, 0.0, 0.02)  # backing off is allowed
    assert base.pose.x < 4.0 and not base.collides(base.pose)


def test_a_moving_robot_covers_its_braking_way() -> None:
    """Standing: where it is; at 1 m/s braking at 0.5 m/s²: the metre ahead, 0.25 m apart."""
    assert braking_poses(Pose2D(1.0, 2.0, 0.5), 0.0, 0.5) == [Pose2D(1.0, 2.0, 0.5)]
    ahead = braking_poses(Pose2D(0.0, 0.0, math.pi / 2), 1.0, 0.5)
    assert [(round(p.x, 9), round(p.y, 9)) for p in ahead] == [
        (0.0, 0.0), (0.0, 0.25), (0.0, 0.5), (0.0, 0.75), (0.0, 1.0)]
    backwards = braking_poses(Pose2D(0.0, 0.0, 0.0), -0.5, 0.5)
    assert backwards[-1].x == pytest.approx(-0.25) and len(backwards) == 2


def test_the_ground_a_braking_robot_covers_is_outlined_round_every_pose_on_its_way() -> None:
    """The swept outline's points lie on the edge of the smallest convex shape holding every
    outline along the braking way, at most 5 cm apart: at 1 m/s forwards the front moves a
    metre, backing the back."""
    body = grown(PIONEER_LX.polygon(), 0.1)
    for pose, speed in ((Pose2D(1.0, 2.0, 0.5), 1.0), (Pose2D(-1.0, 0.0, 2.0), -0.5),
                        (Pose2D(0.0, 0.0, 0.0), 0.0)):
        swept = braking_outline(body, pose, speed, 0.5)
        steps = np.hypot(*np.diff(np.vstack([swept, swept[:1]]), axis=0).T)
        assert steps.max() <= 0.05 + 1e-9
        every = np.vstack([outline_at(body, along) for along in braking_poses(pose, speed, 0.5)])
        hull = every[ConvexHull(every).vertices]
        edges = list(zip(hull, np.roll(hull, -1, axis=0), strict=True))
        for point in swept:
            assert min(segment_distance(point, a, b) for a, b in edges) <= 1e-9
        assert ConvexHull(swept).volume == pytest.approx(ConvexHull(every).volume)
    ahead = braking_outline(body, Pose2D(0.0, 0.0, 0.0), 1.0, 0.5)
    assert ahead[:, 0].max() == pytest.approx(body[:, 0].max() + 1.0)
    assert ahead[:, 0].min() == pytest.approx(body[:, 0].min())


def segment_distance(point: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    """Metres from ``point`` to the segment from ``a`` to ``b``."""
    share = float(np.clip(np.dot(point - a, b - a) / np.dot(b - a, b - a), 0.0, 1.0))
    return float(np.hypot(*(point - a - share * (b - a))))


def test_points_placed_at_several_poses() -> None:
    points = np.array([[1.0, 0.0], [0.0, 1.0]])
    found = placed(points, [Pose2D(0.0, 0.0, 0.0), Pose2D(5.0, 5.0, math.pi / 2)])
    assert np.allclose(found, [[1.0, 0.0], [0.0, 1.0], [5.0, 6.0], [4.0, 5.0]])


def test_an_outline_grown_by_a_margin_keeps_its_shape() -> None:
    assert np.allclose(grown(SQUARE, 0.1), SQUARE * 1.2), "a square 1.2 m wide"
    body = PIONEER_LX.polygon()
    around = grown(body, 0.1)
    assert np.abs(around).max(axis=0) == pytest.approx([0.42, 0.34])
    # a body 0.1 m ahead of another's front touches the other's grown outline
    ahead = outline_at(body, Pose2D(5.0 + 0.32 + 0.1 + 0.32, 0.0, 0.0))
    assert polygon_gap(outline_at(around, Pose2D(5.0, 0.0, 0.0)), ahead) == pytest.approx(
        0.0, abs=1e-9)


def test_far_outlines_are_not_measured_but_near_ones_are_exactly() -> None:
    clearance = np.full((200, 200), 10.0)
    base = RobotBase(clearance, (0.0, 0.0), 0.05, pose=Pose2D(2.0, 5.0, 0.0))
    near, far = square(3.0, 5.0), square(9.0, 5.0)
    base.others = (far, near)
    exact = nearest_gap(outline_at(PIONEER_LX.polygon(), base.pose), [near])
    assert base.robots_gap(base.pose) == pytest.approx(exact)
    assert base.robots_gap(base.pose, below=exact + 0.01) == pytest.approx(exact)
    assert base.robots_gap(base.pose, below=0.1) >= 0.1  # both are further: none measured
    base.others = (far,)  # a new tuple: the bounding circles follow
    assert base.robots_gap(base.pose) > 5.0


@settings(max_examples=200, deadline=None)
@given(x=st.floats(0.5, 9.5), y=st.floats(0.5, 9.5), theta=st.floats(-math.pi, math.pi),
       below=st.floats(0.05, 3.0), others=st.lists(
           st.tuples(st.floats(0.0, 10.0), st.floats(0.0, 10.0), st.floats(-math.pi, math.pi)),
           min_size=1, max_size=4))
def test_the_gap_to_others_is_exact_below_the_limit_wherever_the_body_moved_since(
        x: float, y: float, theta: float, below: float,
        others: list[tuple[float, float, float]]) -> None:
    """The base keeps a bound from where it first measured the others (it skips measuring
    while the nearest is surely further than asked); after a move anywhere, what it returns
    is still the exact gap when that is below the limit, and at least the limit otherwise."""
    clearance = np.full((200, 200), 10.0)
    base = RobotBase(clearance, (0.0, 0.0), 0.05, pose=Pose2D(5.0, 5.0, 0.0))
    base.others = tuple(square(*other) for other in others)
    base.robots_gap(base.pose, below=below)  # the bound is taken here
    moved = Pose2D(x, y, theta)
    exact = nearest_gap(outline_at(PIONEER_LX.polygon(), moved), list(base.others))
    gap = base.robots_gap(moved, below=below)
    if exact < below:
        assert gap == pytest.approx(exact)
    else:
        assert gap >= below
