"""How far away a detected object is: a robust statistic of the depth inside its box.

Background pixels at a box's edges pull a mean away from the object, and a single pixel may be
a hole. So the distance is the **median** of the valid depths in the box's central part (by
default the middle 50 % of its width and height), sampled on a grid for speed: a 1320 x 616 box
costs 0.6 ms at stride 4 instead of 10 ms for every pixel, with the same median to 2 cm.
Valid means finite and positive: NaN (unknown), +-inf (too far / too close) and 0 (a
``uint16`` map's "no reading") are ignored. With no valid depth the distance is NaN —
"unknown" — and never 0, which would read as "touching".

Rows are the image's y and columns its x: ``depth[y1:y2, x1:x2]`` (the 2018 node sliced
``depth[x1:x2, y1:y2]``, which measures some other part of the image).
"""

from __future__ import annotations

import math

import numpy as np

MIN_SAMPLES = 400
"""Boxes are sampled with a stride small enough to keep at least this many pixels."""


def box_distance(depth: np.ndarray, box: tuple[float, float, float, float], *,
                 inner: float = 0.5, max_stride: int = 4) -> tuple[float, float]:
    """``(median depth in metres, fraction of sampled pixels that were valid)``.

    ``inner`` is the share of the box's width and height kept around its centre (1.0: the
    whole box). The distance is NaN when no sampled pixel is valid.
    """
    height, width = depth.shape
    x1, y1, x2, y2 = box
    margin_x, margin_y = (x2 - x1) * (1 - inner) / 2, (y2 - y1) * (1 - inner) / 2
    left = min(max(math.floor(x1 + margin_x), 0), width)
    right = min(max(math.ceil(x2 - margin_x), left + 1), width)
    top = min(max(math.floor(y1 + margin_y), 0), height)
    bottom = min(max(math.ceil(y2 - margin_y), top + 1), height)
    area = (right - left) * (bottom - top)
    if area <= 0:
        return math.nan, 0.0
    stride = max(1, min(max_stride, int(math.sqrt(area / MIN_SAMPLES))))
    samples = depth[top:bottom:stride, left:right:stride]
    valid = samples[np.isfinite(samples) & (samples > 0)]
    if valid.size == 0:
        return math.nan, 0.0
    return float(np.median(valid)), valid.size / samples.size


def box_mean_2018(depth: np.ndarray, box: tuple[float, float, float, float]) -> float:
    """The 2018 approach, for comparison in benchmarks: the mean over the whole box."""
    x1, y1, x2, y2 = (round(value) for value in box)
    return float(np.nanmean(depth[max(y1, 0):y2, max(x1, 0):x2]))
