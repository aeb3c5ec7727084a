"""What a robot's detector saw over a recording: objects per class per minute.

Counted from ``detections`` (``vision_msgs/Detection2DArray``, ROS 2's standard message: each
detection's most likely class) when it was recorded, else from ``predictions`` (the 2018
``cyborg_msgs/Predictions``: each prediction's label), never both, so no object counts twice.
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
