"""Any field a page sends is a number the robot can take or a refusal naming the field: never
another exception (a 400-digit integer or a heading of 1e308 raised OverflowError)."""

from __future__ import annotations

import math
from typing import Any

from hypothesis import given, settings
from hypothesis import strategies as st

from cyborg.monitor.refusal import RefusalError
from cyborg.monitor.robot_fields import (
    ANGLE_LIMIT,
    number_field,
    pose_field,
    tour_points,
)
from cyborg.monitor.robot_wire import WORLD_LIMIT

NUMBERS = st.one_of(st.integers(), st.integers(-10**500, 10**500), st.floats(allow_nan=False),
                    st.sampled_from([1e308, -1e308, 10**400, 2**1024, 0.0, -0.0]))
JSON = st.recursive(st.one_of(st.none(), st.booleans(), NUMBERS, st.text(max_size=5)),
                    lambda inner: st.lists(inner, max_size=4), max_leaves=12)
POSES = st.one_of(st.lists(NUMBERS, min_size=2, max_size=3), JSON)


def _refused_naming(error: RefusalError, field: str) -> bool:
    return error.field is not None and error.field.startswith(field)


@settings(max_examples=150, deadline=None)
@given(vx=JSON, pose=POSES, points=st.lists(POSES, min_size=1, max_size=3))
def test_any_field_is_taken_finite_or_refused_naming_it(vx: Any, pose: Any,
                                                         points: list[Any]) -> None:
    try:
        speed = number_field({"vx": vx}, "vx")
        assert math.isfinite(speed)
    except RefusalError as error:
        assert _refused_naming(error, "vx")
    try:
        x, y, theta = pose_field({"pose": pose}, "pose")
        assert max(abs(x), abs(y)) <= WORLD_LIMIT
        assert theta is None or abs(theta) <= math.tau
    except RefusalError as error:
        assert _refused_naming(error, "pose")
    try:
        for x, y, theta in tour_points({"points": points}):
            assert max(abs(x), abs(y)) <= WORLD_LIMIT
            assert theta is None or abs(theta) <= math.tau
    except RefusalError as error:
        assert _refused_naming(error, "points")


def test_a_heading_past_a_full_turn_is_taken_modulo_one_up_to_its_limit() -> None:
    assert pose_field({"pose": [1, 2, 3.1416]}, "pose")[2] == 3.1416
    assert pose_field({"pose": [1, 2, 5 * math.pi]}, "pose")[2] == math.remainder(
        5 * math.pi, math.tau)
    assert pose_field({"pose": [1, 2, -ANGLE_LIMIT]}, "pose")[2] is not None
