"""Where the robot was at a frame's stamp: stamped poses kept a few seconds, interpolated
between, the heading the short way round; unknown far outside what is kept."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from cyborg.perception.pose_history import AHEAD, BEFORE, MOST, PoseHistory
from cyborg.perception.sighting import RobotPose


def test_a_stamp_between_two_poses_is_interpolated() -> None:
    history = PoseHistory()
    history.add(10.0, RobotPose(0.0, 0.0, 0.0))
    history.add(10.2, RobotPose(0.2, 0.4, 0.4))
    pose = history.at(10.05)
    assert pose is not None
    assert (pose.x, pose.y, pose.theta) == pytest.approx((0.05, 0.1, 0.1))
    assert history.at(10.0) == RobotPose(0.0, 0.0, 0.0)
    assert history.at(10.2) == RobotPose(0.2, 0.4, 0.4)


def test_the_heading_turns_the_short_way_across_pi() -> None:
    history = PoseHistory()
    history.add(1.0, RobotPose(0.0, 0.0, 3.0))
    history.add(2.0, RobotPose(0.0, 0.0, -3.0))  # 0.28 rad further left, not 6 rad back
    pose = history.at(1.5)
    assert pose is not None
    assert abs(pose.theta) == pytest.approx(math.pi)


def test_stamps_a_little_outside_take_the_nearest_pose_and_far_outside_none() -> None:
    history = PoseHistory()
    assert history.at(1.0) is None, "nothing kept"
    history.add(10.0, RobotPose(1.0, 0.0, 0.0))
    history.add(11.0, RobotPose(2.0, 0.0, 0.0))
    assert history.at(11.0 + AHEAD / 2) == RobotPose(2.0, 0.0, 0.0)
    assert history.at(10.0 - BEFORE / 2) == RobotPose(1.0, 0.0, 0.0)
    assert history.at(11.0 + 2 * AHEAD) is None
    assert history.at(10.0 - 2 * BEFORE) is None
    assert history.at(math.nan) is None


def test_only_the_last_span_is_kept_and_a_clock_going_back_starts_over() -> None:
    history = PoseHistory(span=2.0)
    for step in range(50):
        history.add(step * 0.1, RobotPose(step * 0.1, 0.0, 0.0))
    assert len(history) == 21  # 2.9 s back to 4.9 s
    assert history.at(1.0) is None
    history.add(0.5, RobotPose(9.0, 9.0, 0.0))  # a new run of the simulator
    assert len(history) == 1 and history.at(0.5) == RobotPose(9.0, 9.0, 0.0)
    history.add(0.5, RobotPose(8.0, 8.0, 0.0))  # the same stamp again: the newer pose
    assert len(history) == 1 and history.at(0.5) == RobotPose(8.0, 8.0, 0.0)


@given(st.lists(st.floats(-math.pi, math.pi), min_size=2, max_size=20),
       st.floats(0.0, 1.0))
def test_an_interpolated_pose_lies_between_its_neighbours(headings: list[float],
                                                          share: float) -> None:
    """Position on the segment between the two poses around the stamp; heading within the
    smaller angle between theirs."""
    history = PoseHistory(span=100.0)
    for index, heading in enumerate(headings):
        history.add(float(index), RobotPose(float(index), float(index * index), heading))
    stamp = (len(headings) - 1) * share
    pose = history.at(stamp)
    assert pose is not None
    before = min(int(stamp), len(headings) - 2)
    start, end = headings[before], headings[before + 1]
    assert before - 1e-9 <= pose.x <= before + 1 + 1e-9
    apart = abs(math.remainder(end - start, 2 * math.pi))
    assert abs(math.remainder(pose.theta - start, 2 * math.pi)) <= apart + 1e-9
    assert abs(math.remainder(pose.theta - end, 2 * math.pi)) <= apart + 1e-9


def test_poses_stamped_close_together_are_kept_to_a_bound() -> None:
    """A publisher stamping its poses a microsecond apart does not grow the history past MOST:
    the oldest go, the newest are there."""
    history = PoseHistory()
    for step in range(3 * MOST):
        history.add(10.0 + step * 1e-6, RobotPose(float(step), 0.0, 0.0))
    assert len(history) == MOST
    assert history.at(10.0 + (3 * MOST - 1) * 1e-6) == RobotPose(3 * MOST - 1.0, 0.0, 0.0)


@given(st.lists(st.tuples(st.floats(allow_nan=True, allow_infinity=True),
                          st.floats(-1e6, 1e6), st.floats(-1e6, 1e6), st.floats(-10.0, 10.0)),
                max_size=50),
       st.floats(allow_nan=True, allow_infinity=True))
def test_any_stamps_are_kept_or_passed_over_never_raised(
        poses: list[tuple[float, float, float, float]], asked: float) -> None:
    """Stamps out of order, nan or infinite, from anyone on the bus: the history stays within
    its bounds and answers a pose or None for any stamp."""
    history = PoseHistory()
    for stamp, x, y, theta in poses:
        history.add(stamp, RobotPose(x, y, theta))
    assert len(history) <= MOST
    found = history.at(asked)
    assert found is None or math.isfinite(found.x)
