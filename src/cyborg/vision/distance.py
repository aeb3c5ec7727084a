"""How far away a detected object is: a robust statistic of the depth inside its box.

Background pixels at a box's edges pull a mean away from the object, and a single pixel may be
a hole. So the distance is the **median** of the valid depths in the box's central part (by
default the middle 50 % of its width and height), sampled on a regular grid of about 2,500
points for speed: a median over every pixel of a 1320 x 616 box costs 10 ms, over a grid 0.1 ms,
and they agree to a few centimetres (the depth map itself is not finer than that).
Valid means finite and positive: NaN (unknown), +-inf (too far / too close) and 0 (a
``uint16`` map's "no reading") are ignored. With no valid depth the distance is NaN —
"unknown" — and never 0, which would read as "touching".

Rows are the image's y and columns its x: ``depth[y1:y2, x1:x2]`` (the 2018 node sliced
``depth[x1:x2, y1:y2]``, which measures some other part of the image).
"""

from __future__ import annotations

import math

import numpy as np

SAMPLES = 2500
"""About how many depth pixels a box's distance is taken from (all of them in small boxes)."""


def box_distance(depth: np.ndarray, box: tuple[float, float, float, float], *,
                 inner: float = 0.5, samples: int = SAMPLES) -> tuple[float, float]:
    """``(median depth in metres, fraction of sampled pixels that were valid)``.

    ``inner`` is the share of the box's width and height kept around its centre (1.0: the
    whole box); ``samples`` bounds the pixels looked at (the grid's stride grows with the box).
    The distance is NaN when no sampled pixel is valid.
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
    stride = max(1, math.ceil(math.sqrt(area / samples)))
    grid = depth[top:bottom:stride, left:right:stride]
    valid = grid[np.isfinite(grid) & (grid > 0)]
    if valid.size == 0:
        return math.nan, 0.0
    return float(np.median(valid)), valid.size / grid.size


def box_mean_2018(depth: np.ndarray, box: tuple[float, float, float, float]) -> float:
    """The 2018 approach, for comparison in benchmarks: the mean over the whole box."""
    x1, y1, x2, y2 = (round(value) for value in box)
    return float(np.nanmean(depth[max(y1, 0):y2, max(x1, 0):x2]))
