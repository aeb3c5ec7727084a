"""Screening predictions: good ones become detections, bad ones are counted by reason."""

from __future__ import annotations

import math

from hypothesis import given, settings
from hypothesis import strategies as st

from cyborg.interfaces.perception import CAMERA
from cyborg.perception.screening import (
    BAD_CONFIDENCE,
    FLOOD,
    MAX_PER_FRAME,
    NO_DISTANCE,
    OUT_OF_RANGE,
    OUTSIDE_IMAGE,
    UNKNOWN_LABEL,
    screen,
)
from tests.perception.predictions import prediction


def test_a_good_prediction_keeps_its_label_score_distance_and_box_centre() -> None:
    (detection,), rejected = screen([prediction("chair", 3.0, column=100.0, confidence=0.7)])
    assert (detection.label, detection.confidence, detection.distance, detection.column) == (
        "chair", 0.7, 3.0, 100.0)
    assert rejected.total == 0


def test_each_bad_prediction_is_dropped_and_counted_under_its_reason() -> None:
    bad = [prediction(distance=math.nan), prediction(distance=-1.0), prediction(distance=0.0),
           prediction(distance=math.inf), prediction(distance=CAMERA.max_range + 1),
           prediction(column=-50.0), prediction(column=CAMERA.width + 1.0),
           prediction(column=math.nan), prediction(confidence=math.nan),
           prediction(confidence=1.5), prediction(label=""), prediction(label="a\x00b"),
           prediction(label="x" * 100), prediction(label=" "), prediction(label="\u3000")]
    kept, rejected = screen(bad)
    assert kept == []
    assert dict(rejected.counts) == {NO_DISTANCE: 4, OUT_OF_RANGE: 1, OUTSIDE_IMAGE: 3,
                                     BAD_CONFIDENCE: 2, UNKNOWN_LABEL: 5}
    assert rejected.describe() == ("4 no distance, 1 out of range, 3 outside image, "
                                   "2 bad confidence, 5 unknown label")


def test_labels_not_tracked_count_as_unknown_when_some_are_named() -> None:
    kept, rejected = screen([prediction("person"), prediction("unicorn")], labels=["person"])
    assert [d.label for d in kept] == ["person"]
    assert rejected.counts[UNKNOWN_LABEL] == 1


def test_a_box_with_no_corners_is_outside_the_image() -> None:
    empty = prediction()
    empty.bounding_box.points = []
    assert screen([empty])[1].counts[OUTSIDE_IMAGE] == 1


def test_a_flood_keeps_the_most_confident_and_counts_the_rest() -> None:
    flood = [prediction(confidence=(i % 1000) / 1000) for i in range(10_000)]
    kept, rejected = screen(flood)
    assert len(kept) == MAX_PER_FRAME
    assert rejected.counts[FLOOD] == 10_000 - MAX_PER_FRAME
    assert min(d.confidence for d in kept) >= 0.98  # ten of each of the 20 best scores


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.floats(allow_nan=True, allow_infinity=True),
                          st.floats(allow_nan=True, allow_infinity=True),
                          st.floats(allow_nan=True, allow_infinity=True),
                          st.text(max_size=5)), max_size=30))
def test_any_prediction_is_kept_or_counted_never_raised(
        values: list[tuple[float, float, float, str]]) -> None:
    items = [prediction(label, distance, column=column, confidence=confidence)
             for distance, column, confidence, label in values]
    kept, rejected = screen(items)
    assert len(kept) + rejected.total == len(items)
    for detection in kept:
        assert math.isfinite(detection.distance) and detection.distance > 0
        assert 0 <= detection.column <= CAMERA.width
