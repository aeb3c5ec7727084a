"""A robot's topics as the map panel gets them (cyborg.monitor.robot_wire): poses rounded and
NaN ones dropped, scans in whole mm with 0 for no return and -1 for invalid readings, scans of
the wrong shape refused, paths flattened and thinned, batteries clamped; hostile values of any
kind never raise and never make JSON with NaN in it."""

from __future__ import annotations

import json
import math
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cyborg.monitor.robot_wire import (
    PATH_LIMIT,
    SCAN_BEAM_LIMIT,
    TEXT_LIMIT,
    WORLD_LIMIT,
    battery_wire,
    path_wire,
    pose_wire,
    scan_wire,
    state_wire,
    wire_text,
)
from tests.monitor.robot_messages import BEAMS, INCREMENT, battery, path, pose, scan


# ---------------------------------------------------------------------------------- pose
def test_a_pose_is_rounded_to_a_millimetre_and_a_milliradian() -> None:
    payload, warnings = pose_wire(pose(1.23456, -7.0004, 0.12345))
    assert payload == [1.235, -7.0, 0.123] and warnings == []
    wrapped, _ = pose_wire(pose(0.0, 0.0, 3 * math.pi))
    assert wrapped is not None and abs(abs(wrapped[2]) - round(math.pi, 3)) < 1e-9


@pytest.mark.parametrize(("x", "y", "theta", "said"), [
    (math.nan, 0.0, 0.0, "pose: x is nan; last good pose kept"),
    (0.0, math.inf, 0.0, "pose: y is inf; last good pose kept"),
    (0.0, 0.0, -math.inf, "pose: theta is -inf; last good pose kept"),
    (20_000.0, 0.0, 0.0, "more than 10 km from the origin"),
])
def test_a_pose_that_is_not_finite_or_far_away_is_dropped_with_a_warning(
        x: float, y: float, theta: float, said: str) -> None:
    payload, warnings = pose_wire(pose(x, y, theta))
    assert payload is None and len(warnings) == 1 and said in warnings[0]


# ---------------------------------------------------------------------------------- scan
LAST = -math.radians(135) + INCREMENT * (BEAMS - 1)
"""The last beam's angle of a 541-beam scan."""


def test_a_scan_becomes_whole_millimetres_with_0_for_no_return_and_minus_1_for_invalid() -> None:
    ranges = np.full(BEAMS, 2.0, np.float32)
    ranges[:7] = [math.inf, 31.0, math.nan, -math.inf, 0.05, 1.2344, 0.1004]
    payload, warnings = scan_wire(scan(ranges))
    assert warnings == [] and payload is not None
    assert payload["r"][:7] == [0, 0, -1, -1, -1, 1234, 100]
    assert payload["r"][7:] == [2000] * (BEAMS - 7)
    assert payload["mx"] == 30_000
    assert payload["a0"] == pytest.approx(-math.radians(135), abs=1e-6)
    assert payload["da"] == pytest.approx(math.radians(0.5), rel=1e-7)
    json.loads(wire_text({"sc": payload}))


def test_the_simulators_no_return_reads_as_0() -> None:
    """The simulator writes range_max + 1 for a beam that saw nothing (sim/laser.py)."""
    payload, _ = scan_wire(scan(np.full(BEAMS, 31.0, np.float32)))
    assert payload is not None and set(payload["r"]) == {0}


def test_a_valid_reading_never_reads_as_no_return() -> None:
    payload, _ = scan_wire(scan(np.full(BEAMS, 0.0001, np.float32), range_min=0.0))
    assert payload is not None and set(payload["r"]) == {1}


@pytest.mark.parametrize(("kwargs", "said"), [
    ({"beams": 300, "angle_max": LAST},
     "300 ranges where angle_min, angle_max and angle_increment make 541"),
    ({"beams": SCAN_BEAM_LIMIT + 1, "increment": 1e-4}, "more than the 8,192"),
    ({"increment": math.nan, "angle_max": LAST}, "angle_increment is nan"),
    ({"increment": math.inf, "angle_max": LAST}, "angle_increment is inf"),
    ({"increment": 0.0, "angle_max": LAST}, "angle_increment is 0"),
    ({"beams": 1, "angle_min": -2.356, "angle_max": -2.356, "increment": 1e30},
     "angle_increment is 1e+30 rad, more than a full turn"),
    ({"range_max": math.inf}, "range_max is inf"),
    ({"range_max": -1.0}, "range_max is -1 m"),
    ({"angle_min": math.nan}, "angle_min is nan"),
    ({"increment": 1e-300, "angle_max": LAST}, "make far more"),
])
def test_a_scan_of_the_wrong_shape_is_refused_with_a_warning(kwargs: dict[str, Any],
                                                              said: str) -> None:
    payload, warnings = scan_wire(scan(**kwargs))
    assert payload is None and len(warnings) == 1, warnings
    assert said in warnings[0] and warnings[0].startswith("scan: ")



def test_one_beam_more_or_less_than_the_angles_say_is_accepted() -> None:
    """Drivers differ on whether angle_max is the last beam's angle or one past it."""
    for beams in (BEAMS - 1, BEAMS + 1):
        message = scan(np.full(beams, 1.0, np.float32), beams=beams,
                       angle_max=LAST)
        payload, warnings = scan_wire(message)
        assert payload is not None and len(payload["r"]) == beams and warnings == []


# ---------------------------------------------------------------------------------- path
def test_a_path_is_flattened_to_millimetres() -> None:
    payload, warnings = path_wire(path([(0.0, 0.0), (1.2345, -2.0), (3.0, 4.0)]))
    assert payload == {"xy": [0, 0, 1234, -2000, 3000, 4000]} and warnings == []
    empty, _ = path_wire(path([]))
    assert empty == {"xy": []}


def test_poses_that_are_not_finite_or_far_away_are_left_out_of_a_path() -> None:
    payload, warnings = path_wire(path([(0.0, 0.0), (math.nan, 1.0), (1.0, math.inf),
                                        (WORLD_LIMIT * 2, 0.0), (1.0, 1.0)]))
    assert payload == {"xy": [0, 0, 1000, 1000]}
    assert warnings == ["path: 3 poses are not finite or lie more than 10 km away; left out"]


def test_a_long_path_is_thinned_keeping_both_ends() -> None:
    count = PATH_LIMIT * 2 + 7
    payload, warnings = path_wire(path([(i * 0.01, 0.0) for i in range(count)]))
    xy = payload["xy"]
    assert len(xy) // 2 == PATH_LIMIT
    assert xy[:2] == [0, 0] and xy[-2:] == [round((count - 1) * 10), 0]
    assert warnings == [f"path: {count:,} poses, thinned to {PATH_LIMIT:,} for the page"]


# ---------------------------------------------------------------------------------- battery, state
def test_a_battery_is_clamped_and_its_text_clipped() -> None:
    assert battery_wire(battery(87.46)) == ({"pct": 87.5, "charging": False,
                                             "dock": "UNDOCKED"}, [])
    high, warnings = battery_wire(battery(250.0))
    assert high is not None and high["pct"] == 100.0
    assert warnings == ["battery: charge 250 % clamped to 0-100"]
    low, _ = battery_wire(battery(-3.0))
    assert low is not None and low["pct"] == 0.0
    none, warnings = battery_wire(battery(math.nan))
    assert none is None and warnings == ["battery: charge_percent is nan; battery not shown"]
    long, warnings = battery_wire(battery(dock="D" * 5000))
    assert long is not None and len(long["dock"]) == TEXT_LIMIT and len(warnings) == 1


def test_a_path_state_is_clipped() -> None:
    assert state_wire("MOVING_TO_GOAL") == ("MOVING_TO_GOAL", [])
    text, warnings = state_wire("x" * 1000)
    assert len(text) == TEXT_LIMIT and warnings


def test_wire_text_refuses_nan() -> None:
    with pytest.raises(ValueError):
        wire_text({"p": [math.nan]})


# ---------------------------------------------------------------------------------- hostile values
ANY_FLOAT = st.one_of(st.floats(allow_nan=True, allow_infinity=True, width=64),
                      st.sampled_from([0.0, -0.0, 1e-320, 1e308, -1e308, 5e-324]))
FLOAT32 = st.floats(allow_nan=True, allow_infinity=True, width=32)


def _check(payload: object, warnings: list[str]) -> None:
    """Whatever came out is JSON without NaN, and warnings are short lines."""
    json.loads(wire_text({"payload": payload}))
    assert all(isinstance(text, str) and 0 < len(text) < 400 for text in warnings)


@settings(max_examples=200, deadline=None)
@given(x=ANY_FLOAT, y=ANY_FLOAT, theta=ANY_FLOAT)
def test_any_pose_never_raises(x: float, y: float, theta: float) -> None:
    payload, warnings = pose_wire(pose(x, y, theta))
    _check(payload, warnings)
    assert (payload is None) == bool(warnings)


@settings(max_examples=200, deadline=None)
@given(ranges=st.lists(FLOAT32, max_size=64), angle_min=ANY_FLOAT, angle_max=ANY_FLOAT,
       increment=ANY_FLOAT, range_min=ANY_FLOAT, range_max=ANY_FLOAT)
def test_any_scan_never_raises(ranges: list[float], angle_min: float, angle_max: float,
                               increment: float, range_min: float, range_max: float) -> None:
    message = scan(np.asarray(ranges, np.float32), beams=len(ranges), angle_min=angle_min,
                   angle_max=angle_max, increment=increment, range_min=range_min,
                   range_max=range_max)
    payload, warnings = scan_wire(message)
    _check(payload, warnings)
    if payload is not None:
        assert len(payload["r"]) == len(ranges)
        assert all(-1 <= value <= WORLD_LIMIT * 1000 for value in payload["r"])
        assert abs(payload["a0"]) <= math.pi and 0 < abs(payload["da"]) <= math.tau


@settings(max_examples=100, deadline=None)
@given(points=st.lists(st.tuples(ANY_FLOAT, ANY_FLOAT), max_size=40))
def test_any_path_never_raises(points: list[tuple[float, float]]) -> None:
    payload, warnings = path_wire(path(points))
    _check(payload, warnings)
    assert all(abs(value) <= WORLD_LIMIT * 1000 for value in payload["xy"])


@settings(max_examples=100, deadline=None)
@given(charge=ANY_FLOAT, dock=st.text(max_size=300))
def test_any_battery_never_raises(charge: float, dock: str) -> None:
    payload, warnings = battery_wire(battery(charge, dock))
    _check(payload, warnings)
    if payload is not None:
        assert 0.0 <= payload["pct"] <= 100.0
