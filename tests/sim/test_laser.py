"""The laser's beams as map points, and the nearest return in the corridors ahead of the robot."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cyborg.sim.follower import front_ranges
from cyborg.sim.laser import Laser, LaserSpec


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
