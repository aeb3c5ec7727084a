"""A detection's world position: pose + camera mount + bearing + distance."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from cyborg.interfaces.perception import CAMERA, CameraMount
from cyborg.perception.sighting import Detection, RobotPose, locate

AT_CENTRE = CameraMount(x=0.0, y=0.0, z=1.0, yaw=0.0)


def test_straight_ahead_lies_on_the_robots_heading_past_the_mount() -> None:
    mount = CameraMount(x=0.3, y=0.0, z=1.0, yaw=0.0)
    (seen,) = locate([Detection("person", 0.9, 2.0, CAMERA.centre_column)],
                     RobotPose(1.0, 2.0, math.pi / 2), mount=mount)
    assert (seen.x, seen.y) == pytest.approx((1.0, 4.3))
    assert seen.distance == pytest.approx(2.3) and seen.bearing == pytest.approx(0.0)


def test_left_of_the_image_centre_is_left_of_the_robot() -> None:
    column = CAMERA.column(math.radians(30))
    (seen,) = locate([Detection("person", 0.9, 2.0, column)], RobotPose(0, 0, 0),
                     mount=AT_CENTRE)
    # depth 2 m along the axis, so 2 * tan(30°) to the left
    assert (seen.x, seen.y) == pytest.approx((2.0, 2.0 * math.tan(math.radians(30))))
    assert seen.bearing == pytest.approx(math.radians(30))


def test_a_camera_looking_sideways_turns_what_it_sees() -> None:
    mount = CameraMount(x=0.0, y=0.5, z=1.0, yaw=math.pi / 2)
    (seen,) = locate([Detection("person", 0.9, 1.0, CAMERA.centre_column)],
                     RobotPose(0, 0, 0), mount=mount)
    assert (seen.x, seen.y) == pytest.approx((0.0, 1.5))


@given(st.floats(-50, 50), st.floats(-50, 50), st.floats(-math.pi, math.pi),
       st.floats(0.5, 15), st.floats(-0.9, 0.9))
def test_the_sighting_lies_at_its_distance_and_bearing_from_the_robot(
        x: float, y: float, theta: float, depth: float, bearing: float) -> None:
    column = CAMERA.column(bearing)
    (seen,) = locate([Detection("person", 0.9, depth, column)], RobotPose(x, y, theta),
                     mount=AT_CENTRE)
    assert math.hypot(seen.x - x, seen.y - y) == pytest.approx(depth / math.cos(bearing))
    assert seen.bearing == pytest.approx(bearing, abs=1e-9)
    heading = math.atan2(seen.y - y, seen.x - x)
    assert math.remainder(heading - theta - bearing, 2 * math.pi) == pytest.approx(0, abs=1e-7)


def test_nothing_placed_from_nothing() -> None:
    assert locate([], RobotPose(0, 0, 0)) == []
