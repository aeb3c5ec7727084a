"""The laser's beams as map points, and the nearest return in the corridors ahead of the robot."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import ndimage

from cyborg.sim.follower import front_ranges
from cyborg.sim.laser import Laser, LaserSpec, cast_rays, cast_rays_far, room_grid


def test_the_points_of_a_scan_are_where_its_valid_beams_end() -> None:
    """Beam k leaves the scanner (mount_x ahead of the robot) at heading + its angle; beams
    reading more than range_max (nothing seen) and nan give no point; the order is kept."""
    spec = LaserSpec(beams=5, field_of_view=math.pi, mount_x=0.2, noise=0.0)
    laser = Laser(np.zeros((10, 10), np.bool_), (0.0, 0.0), 1.0, spec)
    ranges = np.array([1.0, spec.range_max + 1.0, 2.0, math.nan, 3.0])
    points = laser.points(1.0, 2.0, math.pi / 2, ranges)  # facing +y: scanner at (1, 2.2)
    assert points == pytest.approx(np.array([[2.0, 2.2], [1.0, 4.2], [-2.0, 2.2]]))


def test_the_nearest_return_ahead_is_measured_within_each_corridor() -> None:
    """Along the heading to the nearest return less than a corridor's half width aside; beams
    behind, beyond range_max or nan do not count; inf where a corridor is clear."""
    angles = np.array([0.0, math.atan2(0.4, 2.0), math.atan2(-0.1, 3.0), math.pi, 0.05])
    ranges = np.array([5.0, math.hypot(2.0, 0.4), math.hypot(3.0, 0.1), 0.5, math.nan])
    assert front_ranges(ranges, angles, (0.3, 0.5)) == pytest.approx((3.0, 2.0))
    assert front_ranges(ranges, angles, (0.05,)) == (5.0,)
    assert front_ranges(ranges, angles, (0.05,), range_max=4.0) == (math.inf,)


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**31), st.floats(0.0, 0.05), st.floats(1.0, 40.0))
def test_leaping_through_open_space_finds_the_walls_the_cell_walk_finds(
        seed: int, density: float, reach: float) -> None:
    """Random walls (scattered cells and straight walls), a scanner anywhere, every beam: the
    same range (to rounding), nothing seen where nothing is."""
    random = np.random.default_rng(seed)
    occupied = random.random((120, 90)) < density
    occupied[random.integers(120), :] = True
    occupied[:, random.integers(90)] = True
    clearance = (ndimage.distance_transform_edt(~occupied) * 0.05).astype(np.float32)
    x, y = random.uniform(-1.0, 5.5), random.uniform(-1.0, 7.0)
    angles = random.uniform(-math.pi, math.pi, 361)
    angles[:4] = (0.0, math.pi / 2, math.pi, -math.pi / 2)  # along the grid's lines
    walked, leapt = np.empty(361), np.empty(361)
    cast_rays(occupied, 0.0, 1.0, 0.05, x, y, angles, reach, walked)
    cast_rays_far(room_grid(occupied, clearance, 0.05), 0.0, 1.0, 0.05, x, y, angles, reach,
                  leapt)
    assert np.array_equal(np.isfinite(walked), np.isfinite(leapt))
    assert leapt[np.isfinite(leapt)] == pytest.approx(walked[np.isfinite(walked)], abs=1e-9)


def test_a_scanner_that_stands_sees_the_same_walls_and_what_moves() -> None:
    """Scanned twice from one pose, with a body come into view the second time: the walls are
    the same, the body is seen."""
    occupied = np.zeros((100, 100), np.bool_)
    occupied[:, 90] = True  # a wall 4.5 m ahead
    laser = Laser(occupied, (0.0, 0.0), 0.05, LaserSpec(beams=3, field_of_view=0.2, noise=0.0,
                                                        mount_x=0.0))
    first = laser.scan(0.0, 2.5, 0.0)
    assert first == pytest.approx([4.5 / math.cos(0.1), 4.5, 4.5 / math.cos(0.1)], abs=0.06)
    box = np.array([[2.0, 2.3], [2.4, 2.3], [2.4, 2.7], [2.0, 2.7]])
    second = laser.scan(0.0, 2.5, 0.0, (box,))
    assert second[1] == pytest.approx(2.0) and second[[0, 2]] == pytest.approx(first[[0, 2]])
    assert laser.scan(0.0, 2.5, 0.0) == pytest.approx(first)
