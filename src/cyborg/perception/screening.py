"""Screening the detector's predictions: what can be placed on the map, and why the rest cannot.

The tracker takes predictions from a topic anyone may publish on, so it expects anything. Each
prediction of a ``cyborg_msgs/Predictions`` message either becomes a
:class:`~cyborg.perception.sighting.Detection` or is counted under one reason:

==================  ==========================================================================
reason              the prediction
==================  ==========================================================================
``no distance``     has a distance that is NaN, infinite, zero or negative (no depth)
``out of range``    is nearer or farther than the camera measures (0.3 to 20 m for the ZED 2)
``outside image``   has a box whose centre is not finite or lies outside the image's columns,
                    or a box with no corners
``bad confidence``  has a confidence that is NaN or outside 0..1
``unknown label``   has an empty label (or only spaces), one longer than :data:`MAX_LABEL`,
                    one with control characters, or one not among the labels tracked (when
                    some are named)
``flood``           came beyond the :data:`MAX_PER_FRAME` most confident of its message
==================  ==========================================================================

Nothing raises: a bad prediction is dropped and counted (:class:`Rejections`), and the tracker's
node logs the counts, rate-limited. A message of 10,000 predictions costs one pass over them
and keeps only the most confident :data:`MAX_PER_FRAME`, so the tracker never stalls on it.
"""

from __future__ import annotations

import heapq
import math
from collections import Counter
from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Any

from cyborg.interfaces.perception import CAMERA, CameraModel
from cyborg.perception.sighting import Detection

MAX_PER_FRAME = 200
"""Predictions taken from one message at most (the most confident); the rest count as flood."""
MAX_LABEL = 64
"""Characters a label may have."""

NO_DISTANCE = "no distance"
OUT_OF_RANGE = "out of range"
OUTSIDE_IMAGE = "outside image"
BAD_CONFIDENCE = "bad confidence"
UNKNOWN_LABEL = "unknown label"
FLOOD = "flood"
REASONS = (NO_DISTANCE, OUT_OF_RANGE, OUTSIDE_IMAGE, BAD_CONFIDENCE, UNKNOWN_LABEL, FLOOD)
"""Every reason a prediction is dropped for, in the order the log lists them."""


@dataclass
class Rejections:
    """Predictions dropped, counted by reason (:data:`REASONS`)."""

    counts: Counter[str] = field(default_factory=Counter)

    @property
    def total(self) -> int:
        """How many were dropped, for whatever reason."""
        return sum(self.counts.values())

    def add(self, other: Rejections) -> None:
        """Count ``other``'s too."""
        self.counts.update(other.counts)

    def describe(self) -> str:
        """``"3 no distance, 1 flood"``: the non-zero counts in the order of :data:`REASONS`."""
        return ", ".join(f"{self.counts[reason]} {reason}" for reason in REASONS
                         if self.counts[reason])


def _label_ok(label: str, labels: frozenset[str]) -> bool:
    if not label.strip() or len(label) > MAX_LABEL or not label.isprintable():
        return False
    return not labels or label in labels


def _centre_column(polygon: Any) -> float:
    points = polygon.points
    if not len(points):
        return math.nan
    return float(sum(float(point.x) for point in points) / len(points))


def screen(predictions: Iterable[Any], camera: CameraModel = CAMERA,
           labels: Iterable[str] = (), limit: int = MAX_PER_FRAME
           ) -> tuple[list[Detection], Rejections]:
    """The predictions that can be placed (the ``limit`` most confident), and the rest counted.

    ``predictions`` are ``cyborg_msgs/Prediction`` messages (or anything with ``label``,
    ``confidence``, ``distance`` and ``bounding_box.points``); ``labels`` names those to keep
    (none: every well-formed label).
    """
    wanted = frozenset(labels)
    rejected = Rejections()
    kept: list[Detection] = []
    for prediction in predictions:
        reason = _reason(prediction, camera, wanted)
        if isinstance(reason, str):
            rejected.counts[reason] += 1
        else:
            kept.append(reason)
    if len(kept) > limit:
        rejected.counts[FLOOD] += len(kept) - limit
        kept = heapq.nlargest(limit, kept, key=lambda detection: detection.confidence)
    return kept, rejected


def _reason(prediction: Any, camera: CameraModel, labels: frozenset[str]) -> Detection | str:
    """The detection of ``prediction``, or the reason it cannot be one."""
    label = prediction.label
    if not isinstance(label, str) or not _label_ok(label, labels):
        return UNKNOWN_LABEL
    confidence = float(prediction.confidence)
    if not 0.0 <= confidence <= 1.0:  # NaN fails both comparisons
        return BAD_CONFIDENCE
    distance = float(prediction.distance)
    if not (math.isfinite(distance) and distance > 0):
        return NO_DISTANCE
    if not camera.min_range <= distance <= camera.max_range:
        return OUT_OF_RANGE
    column = _centre_column(prediction.bounding_box)
    if not (math.isfinite(column) and 0.0 <= column <= camera.width):
        return OUTSIDE_IMAGE
    return Detection(label, confidence, distance, column)
