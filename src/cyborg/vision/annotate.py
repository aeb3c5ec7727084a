"""The annotated image: each detection's box with its label, confidence and distance."""

from __future__ import annotations

import math
from collections.abc import Sequence

import cv2
import numpy as np

from cyborg.vision.detector import Detection

BOX_COLOUR = (0, 200, 0)
TEXT_COLOUR = (0, 0, 0)
LABEL_BACKGROUND = (255, 255, 255)


def caption(detection: Detection) -> str:
    """``"person: 0.93 (2.37 m)"``, or ``"person: 0.93 (? m)"`` when the distance is unknown."""
    distance = "?" if math.isnan(detection.distance) else f"{detection.distance:.2f}"
    return f"{detection.label}: {detection.confidence:.2f} ({distance} m)"


def annotate(image: np.ndarray, detections: Sequence[Detection]) -> np.ndarray:
    """A copy of ``image`` with the detections drawn on it (the input is left unchanged)."""
    return draw_detections(image.copy(), detections)


def draw_detections(drawn: np.ndarray, detections: Sequence[Detection]) -> np.ndarray:
    """Draws the detections on ``drawn`` itself (a writable BGR image) and returns it."""
    height, width = drawn.shape[:2]
    scale = max(0.4, min(width, height) / 1000)
    thickness = max(1, round(scale * 2))
    for detection in detections:
        x1, y1, x2, y2 = (round(value) for value in detection.box)
        cv2.rectangle(drawn, (x1, y1), (x2, y2), BOX_COLOUR, thickness)
        text = caption(detection)
        (text_w, text_h), baseline = cv2.getTextSize(text, cv2.FONT_HERSHEY_SIMPLEX, scale, 1)
        top = y1 - text_h - baseline - 2 if y1 - text_h - baseline - 2 >= 0 else y1
        cv2.rectangle(drawn, (x1, top), (x1 + text_w + 2, top + text_h + baseline + 2),
                      LABEL_BACKGROUND, cv2.FILLED)
        cv2.putText(drawn, text, (x1 + 1, top + text_h + 1), cv2.FONT_HERSHEY_SIMPLEX, scale,
                    TEXT_COLOUR, 1, cv2.LINE_AA)
    return drawn
