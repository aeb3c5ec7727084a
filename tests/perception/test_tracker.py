"""Tracking: one object per label and place, with an id, velocity, confidence; forgetting."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cyborg.interfaces.perception import CAMERA, CAMERA_MOUNT
from cyborg.perception.sighting import Detection, RobotPose, Sighting
from cyborg.perception.tracker import Tracker, TrackerSettings, track_frames


def seen(label: str, x: float, y: float, confidence: float = 0.8) -> Sighting:
    return Sighting(label, confidence, x, y, math.hypot(x, y), math.atan2(y, x))


def test_repeated_sightings_near_one_place_are_one_object_that_grows_in_confidence() -> None:
    tracker = Tracker()
    confidences = []
    for step in range(5):
        tracker.update(step * 0.1, [seen("person", 2.0 + 0.05 * (step % 2), 1.0)])
        (item,) = tracker.objects()
        confidences.append(item.confidence)
    assert item.id == 1 and item.times_seen == 5
    assert confidences == sorted(confidences) and confidences[-1] > 0.8 > confidences[1]
    assert item.confidence_at(item.last_seen + 1.0) == pytest.approx(item.confidence / 2)


def test_a_walking_person_gets_a_velocity_and_stays_one_object() -> None:
    tracker = Tracker()
    for step in range(40):  # 1 m/s along x, seen 10 times a second
        tracker.update(step * 0.1, [seen("person", 1.0 + step * 0.1, 0.0)])
    (item,) = tracker.objects()
    assert (item.vx, item.vy) == pytest.approx((1.0, 0.0), abs=0.1)
    assert item.x == pytest.approx(4.9, abs=0.1)


def test_far_apart_or_differently_labelled_sightings_are_different_objects() -> None:
    tracker = Tracker()
    tracker.update(0.0, [seen("person", 0, 0), seen("person", 3, 0), seen("chair", 0, 0.1)])
    tracker.update(0.1, [seen("person", 0.1, 0), seen("person", 3.1, 0), seen("chair", 0, 0.1)])
    items = tracker.objects()
    assert sorted((item.label, item.times_seen) for item in items) == [
        ("chair", 2), ("person", 2), ("person", 2)]
    assert len({item.id for item in items}) == 3


def test_nearest_pairs_are_joined_first() -> None:
    tracker = Tracker(TrackerSettings(gate=2.0))
    tracker.update(0.0, [seen("person", 0, 0), seen("person", 1.5, 0)])
    first, second = tracker.objects()
    tracker.update(0.1, [seen("person", 1.4, 0), seen("person", 0.2, 0)])
    assert (first.times_seen, second.times_seen) == (2, 2)
    assert first.x < 0.2 and second.x > 1.4


def test_an_unseen_object_is_forgotten_after_the_timeout_and_ids_are_not_reused() -> None:
    tracker = Tracker(TrackerSettings(forget_after=2.0))
    tracker.update(0.0, [seen("person", 0, 0)])
    tracker.update(1.9, [])
    assert len(tracker) == 1
    tracker.update(2.1, [seen("person", 5, 5)])
    assert [(item.id, item.x) for item in tracker.objects()] == [(2, 5)]


def test_time_going_back_starts_afresh() -> None:
    tracker = Tracker(TrackerSettings(forget_after=2.0))
    tracker.update(100.0, [seen("person", 0, 0)])
    tracker.update(1.0, [seen("chair", 1, 1)])
    assert [item.label for item in tracker.objects()] == ["chair"]


def test_too_many_objects_drop_the_least_confident() -> None:
    tracker = Tracker(TrackerSettings(max_objects=3))
    tracker.update(0.0, [seen("person", 10.0 * i, 0, confidence=0.1 * (i + 1))
                         for i in range(6)])
    assert sorted(round(item.x) for item in tracker.objects()) == [30, 40, 50]


def test_settings_that_make_no_tracker_are_refused_by_name() -> None:
    with pytest.raises(ValueError, match="gate"):
        TrackerSettings(gate=-1.0)
    with pytest.raises(ValueError, match="alpha"):
        TrackerSettings(alpha=0.0)
    with pytest.raises(ValueError, match="max_objects"):
        TrackerSettings(max_objects=0)
    with pytest.raises(ValueError, match="stamp"):
        Tracker().update(math.nan, [])


@settings(max_examples=40, deadline=None)
@given(st.lists(st.lists(st.tuples(st.sampled_from(["person", "chair", "dog"]),
                                   st.floats(-5, 5), st.floats(-5, 5)), max_size=8),
                min_size=1, max_size=12))
def test_tracking_never_mixes_labels(frames: list[list[tuple[str, float, float]]]) -> None:
    tracker = Tracker()
    labels_of: dict[int, str] = {}
    for step, frame in enumerate(frames):
        tracker.update(step * 0.1, [seen(label, x, y) for label, x, y in frame])
        for item in tracker.objects():
            assert labels_of.setdefault(item.id, item.label) == item.label
        # every sighting was taken: by an object of its label, seen at this stamp
        for label in {label for label, _, _ in frame}:
            count = sum(1 for other, _, _ in frame if other == label)
            fresh = [item for item in tracker.objects()
                     if item.label == label and item.last_seen == step * 0.1]
            assert 1 <= len(fresh) <= count


def test_track_frames_follows_a_person_seen_by_a_turning_robot() -> None:
    frames = []
    for step in range(20):  # the person stands at (3, 1); the robot turns on the spot
        theta = 0.02 * step
        camera_x, camera_y = 0.2 * math.cos(theta), 0.2 * math.sin(theta)  # 0.2 m ahead
        bearing = math.atan2(1.0 - camera_y, 3.0 - camera_x) - theta
        depth = math.hypot(3.0 - camera_x, 1.0 - camera_y) * math.cos(bearing)
        frames.append((step * 0.1, RobotPose(0.0, 0.0, theta),
                       [Detection("person", 0.9, depth, CAMERA.column(bearing))]))
    assert CAMERA_MOUNT.x == 0.2 and CAMERA_MOUNT.yaw == 0.0
    *_, last = track_frames(frames)
    (person,) = last
    assert (person.x, person.y) == pytest.approx((3.0, 1.0), abs=0.05)


@settings(max_examples=25, deadline=None)
@given(st.floats(-20, 20), st.floats(-20, 20), st.integers(0, 2**32 - 1))
def test_a_person_standing_still_seen_with_noise_is_one_object_near_where_they_stand(
        x: float, y: float, seed: int) -> None:
    rng = np.random.default_rng(seed)
    tracker = Tracker()
    for step in range(30):
        noise = rng.normal(0.0, 0.1, 2)
        tracker.update(step / 15, [seen("person", x + noise[0], y + noise[1])])
    (person,) = tracker.objects()
    assert math.hypot(person.x - x, person.y - y) < 0.3
    assert math.hypot(person.vx, person.vy) < 0.6  # noise reads as a little speed


@settings(max_examples=30, deadline=None)
@given(st.lists(st.lists(st.tuples(st.floats(-1e6, 1e6), st.floats(-1e6, 1e6),
                                   st.floats(0, 1)), max_size=40), max_size=6),
       st.integers(1, 20))
def test_any_sightings_keep_the_tracker_bounded(frames: list[list[tuple[float, float, float]]],
                                                max_objects: int) -> None:
    tracker = Tracker(TrackerSettings(max_objects=max_objects))
    for step, frame in enumerate(frames):
        tracker.update(step * 0.05, [seen("person", x, y, c) for x, y, c in frame])
        assert len(tracker) <= max_objects
        for item in tracker.objects():
            assert 0.0 <= item.confidence <= 1.0
            assert math.hypot(item.vx, item.vy) <= tracker.settings.max_speed + 1e-9
