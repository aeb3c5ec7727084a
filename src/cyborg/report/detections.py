"""What a robot saw over a recording, per class and minute: objects tracked, and detections.

Two different counts, each named for what it counts:

* **tracked objects** (:func:`tracked_counts`), from the tracker's ``<robot>/objects``
  (``cyborg_msgs/TrackedObjects``): the distinct track ids listed in each minute, and over the
  whole run. Three people walking in front of the robot for a minute are three (or a few more
  where the tracker lost one and found them again);
* **detections** (:func:`detection_counts`), one per object per camera frame: from
  ``detections`` (``vision_msgs/Detection2DArray``, ROS 2's standard message: each detection's
  most likely class) when it was recorded, else from ``predictions`` (the 2018
  ``cyborg_msgs/Predictions``: each prediction's label), never both. Three people in view for a
  minute at 10 frames a second are about 1,800 detections.

Minute 0 starts with the recording's first message.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field
from typing import Any

from cyborg.report.recording import Stamped


@dataclass
class DetectionCounts:
    """Objects seen per minute and class; :attr:`source` names the topic counted."""

    source: str = ""
    per_minute: dict[int, Counter[str]] = field(default_factory=dict)
    distinct: Counter[str] | None = None
    """Tracked objects only: distinct ids per class over the whole run (one person seen in
    three minutes is one); None for detections, whose totals are the minutes' sums."""

    @property
    def classes(self) -> list[str]:
        """Every class seen, the most frequent first."""
        total = self.totals
        return sorted(total, key=lambda label: (-total[label], label))

    def seen(self, minute: int, label: str) -> int:
        """Objects of class ``label`` seen in ``minute``."""
        counts = self.per_minute.get(minute)
        return counts[label] if counts is not None else 0

    @property
    def totals(self) -> Counter[str]:
        """Objects seen per class over the whole recording."""
        if self.distinct is not None:
            return self.distinct
        total: Counter[str] = Counter()
        for counts in self.per_minute.values():
            total.update(counts)
        return total


def detection_counts(detections: tuple[str, list[Stamped]],
                     predictions: tuple[str, list[Stamped]], start: int) -> DetectionCounts:
    """Counts per minute from ``(topic, messages)`` of detections, else of predictions."""
    topic, messages = detections if detections[1] else predictions
    labels = _detection_labels if detections[1] else _prediction_labels
    result = DetectionCounts(topic if messages else "")
    for item in messages:
        minute = max(0, (item.log_time - start) // 60_000_000_000)
        result.per_minute.setdefault(int(minute), Counter()).update(labels(item.message))
    return result


def tracked_counts(topic: str, messages: list[Stamped], start: int) -> DetectionCounts:
    """Distinct track ids per minute and class in ``objects`` messages (none: no source)."""
    result = DetectionCounts(topic if messages else "", distinct=Counter())
    ids: dict[int, dict[str, set[int]]] = {}
    everyone: dict[str, set[int]] = {}
    for item in messages:
        minute = int(max(0, (item.log_time - start) // 60_000_000_000))
        for tracked in item.message.objects:
            label = str(tracked.label) or "?"
            ids.setdefault(minute, {}).setdefault(label, set()).add(int(tracked.id))
            everyone.setdefault(label, set()).add(int(tracked.id))
    for minute, labels in ids.items():
        result.per_minute[minute] = Counter({label: len(found) for label, found in labels.items()})
    result.distinct = Counter({label: len(found) for label, found in everyone.items()})
    return result


def _detection_labels(message: Any) -> list[str]:
    found = []
    for detection in message.detections:
        results = list(detection.results)
        if results:
            best = max(results, key=lambda result: float(result.hypothesis.score))
            found.append(str(best.hypothesis.class_id) or "?")
        else:
            found.append("?")
    return found


def _prediction_labels(message: Any) -> list[str]:
    return [str(prediction.label) or "?" for prediction in message.predictions]
