"""The camera model of :mod:`cyborg.interfaces.perception`: bearings and columns agree, the
image's edges are half the field of view away, left is positive."""

from __future__ import annotations

import math

from hypothesis import given
from hypothesis import strategies as st

from cyborg.interfaces.perception import CAMERA, OBJECTS, SAY, CameraModel


def test_the_image_edges_lie_half_the_field_of_view_away_and_left_is_positive() -> None:
    assert math.isclose(CAMERA.bearing(0.0), CAMERA.horizontal_fov / 2)
    assert math.isclose(CAMERA.bearing(CAMERA.width), -CAMERA.horizontal_fov / 2)
    assert CAMERA.bearing(CAMERA.width / 2) == 0.0


@given(st.floats(min_value=-1.0, max_value=1.0))
def test_a_bearing_seen_at_its_column_gives_the_bearing_back(bearing: float) -> None:
    camera = CameraModel(width=640, height=480, horizontal_fov=math.radians(120), min_range=0.1,
                         max_range=10.0)
    assert math.isclose(camera.bearing(camera.column(bearing)), bearing, abs_tol=1e-9)


def test_the_topics_are_relative_to_the_robot_and_typed() -> None:
    assert OBJECTS.full_name("/robot1") == "/robot1/objects"
    assert SAY.full_name("/cyborg") == "/cyborg/say"
    assert OBJECTS.type_name == "cyborg_msgs/msg/TrackedObjects"
    assert SAY.type_name == "std_msgs/msg/String"
    assert not OBJECTS.latched
