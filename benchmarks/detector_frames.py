"""The detector benchmark's frames, statistics and camera side, shared by both approaches.

* :func:`make_frames`: four scikit-image photos (Middlebury motorcycle, astronaut, coffee, cat)
  tiled into a 1920x1080 BGR image, with a float32 depth map in metres of the same size (the
  motorcycle's ground-truth depth, synthetic depth elsewhere) with NaN, +inf, -inf and 0 holes;
  four variants (the tiles in other places), so consecutive frames are different memory.
* :class:`Run`: one configuration's samples per stage, latencies and frames per second.
* :class:`Offer` and :func:`offer_frames`: the camera's side of a run, keeping a number of
  frames in flight and timing their answers.
"""

from __future__ import annotations

import importlib
import math
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import cv2
import numpy as np

WIDTH, HEIGHT = 1920, 1080
THRESHOLD = 0.5  # ours: Detector's default; 2018: dynamic reconfigure's default
STAGES = ("transport", "message → frame", "preprocess", "inference", "postprocess", "distance",
          "drawing", "publish")
WAIT = 2.0  # seconds without an answer before a frame counts as lost


# ---------------------------------------------------------------------- frames
def _fit(image: np.ndarray, width: int, height: int) -> np.ndarray:
    """``image`` scaled to ``height`` (aspect kept), centred on a grey cell of width x height."""
    new_w = min(width, round(image.shape[1] * height / image.shape[0]))
    cell = np.full((height, width, 3), 96, np.uint8)
    left = (width - new_w) // 2
    cell[:, left:left + new_w] = cv2.resize(image, (new_w, height), interpolation=cv2.INTER_AREA)
    return cell


def _cell_depth(kind: int, width: int, height: int, rng: np.random.Generator,
                motorcycle: np.ndarray) -> np.ndarray:
    """Depth in metres for one tile: the motorcycle's ground truth, or a floor with an object."""
    if kind == 0:
        new_w = round(motorcycle.shape[1] * height / motorcycle.shape[0])
        depth = np.full((height, width), 6.0, np.float32)
        left = (width - new_w) // 2
        depth[:, left:left + new_w] = cv2.resize(motorcycle, (new_w, height),
                                                 interpolation=cv2.INTER_NEAREST)
        return depth
    rows = np.linspace(4.0, 1.5, height, dtype=np.float32)[:, None]  # floor: far at the top
    depth = np.repeat(rows, width, axis=1)
    yy, xx = np.mgrid[0:height, 0:width]
    inside = ((xx - width / 2) / (width * 0.3)) ** 2 + ((yy - height / 2) / (height * 0.45)) ** 2
    depth[inside < 1] = 0.8 + 0.4 * kind  # the object, nearer than the floor
    depth += rng.normal(0, 0.01, depth.shape).astype(np.float32)
    return depth


def make_frames(variants: int = 4) -> list[tuple[np.ndarray, np.ndarray]]:
    """1920x1080 BGR images with depth maps (float32 metres, NaN/inf/0 holes)."""
    data: Any = importlib.import_module("skimage.data")  # a dev extra, untyped
    left, _right, disparity = data.stereo_motorcycle()
    focal, baseline, doffs = 994.978, 0.193001, 31.086  # the dataset's calibration
    with np.errstate(invalid="ignore"):
        motorcycle = np.where(np.isfinite(disparity), focal * baseline / (disparity + doffs),
                              np.nan).astype(np.float32)
    photos = [left, data.astronaut(), data.coffee(), data.chelsea()]
    cell_w, cell_h = WIDTH // 2, HEIGHT // 2
    cells = [_fit(cv2.cvtColor(photo, cv2.COLOR_RGB2BGR), cell_w, cell_h) for photo in photos]
    rng = np.random.default_rng(7)
    depths = [_cell_depth(kind, cell_w, cell_h, rng, motorcycle) for kind in range(4)]
    frames = []
    for variant in range(variants):
        order = [(index + variant) % 4 for index in range(4)]
        image = np.vstack([np.hstack([cells[order[0]], cells[order[1]]]),
                           np.hstack([cells[order[2]], cells[order[3]]])])
        depth = np.vstack([np.hstack([depths[order[0]], depths[order[1]]]),
                           np.hstack([depths[order[2]], depths[order[3]]])])
        holes = rng.random(depth.shape) < 0.05
        depth[holes] = np.nan  # stereo matcher: no match
        depth[:60, :] = np.inf  # too far
        depth[-40:, :200] = 0.0  # no reading
        depth[300:340, 900:1100] = -np.inf  # too close
        frames.append((np.ascontiguousarray(image), np.ascontiguousarray(depth)))
    return frames


# ---------------------------------------------------------------------- statistics
def quantiles(samples: Sequence[float]) -> tuple[float, float]:
    """Median and 90th percentile (NaN, NaN when empty)."""
    if not samples:
        return math.nan, math.nan
    values = np.asarray(samples, dtype=np.float64)
    return float(np.median(values)), float(np.percentile(values, 90))


@dataclass
class Run:
    """One configuration's samples (milliseconds), pooled over rounds, and FPS per round."""

    name: str
    stages: dict[str, list[float]] = field(default_factory=dict)
    latency: list[float] = field(default_factory=list)
    fps_rounds: list[float] = field(default_factory=list)
    detections: list[float] = field(default_factory=list)
    frames: int = 0
    lost: int = 0
    paired: list[float] = field(default_factory=list)
    """Overheads over bare inference measured in pairs (:meth:`PipelineAlone.paired`)."""
    paired_bare: list[float] = field(default_factory=list)
    """The bare inference of each pair, ms."""
    inference_rounds: list[float] = field(default_factory=list)
    """Per round, the median time of the network's inference, ms (NaN where not measured)."""

    def add(self, other: Run) -> None:
        for stage, samples in other.stages.items():
            self.stages.setdefault(stage, []).extend(samples)
        self.latency += other.latency
        self.fps_rounds += other.fps_rounds
        self.detections += other.detections
        self.frames += other.frames
        self.lost += other.lost
        self.paired += other.paired
        self.paired_bare += other.paired_bare
        self.inference_rounds += other.inference_rounds or [
            quantiles(other.stages.get("inference", []))[0]] * len(other.fps_rounds)

    def stage(self, name: str) -> tuple[float, float]:
        return quantiles(self.stages.get(name, []))

    @property
    def fps(self) -> float:
        """The median over rounds (a round's rate: frames answered per second)."""
        return quantiles(self.fps_rounds)[0]

    def fps_at_full_speed(self, limit_ms: float) -> tuple[float, int]:
        """The median FPS over the rounds whose inference took at most ``limit_ms`` (the
        machine's two cores at work), and how many rounds that is."""
        rates = [fps for fps, inference in zip(self.fps_rounds, self.inference_rounds,
                                               strict=True) if inference <= limit_ms]
        return quantiles(rates)[0], len(rates)

    @property
    def per_frame_ms(self) -> float:
        return 1000.0 / self.fps if self.fps > 0 else math.nan

    @classmethod
    def inference_alone(cls, samples_ms: list[float]) -> Run:
        """One round of bare inference: its calls' times, and its rate, calls per second of
        calls (the mean, like the configurations' frames per second: a slow call counts)."""
        run = cls("")
        run.stages["inference"] = samples_ms
        run.fps_rounds = [1000.0 * len(samples_ms) / sum(samples_ms)] if samples_ms else []
        return run


Frames = list[tuple[np.ndarray, np.ndarray]]


# ---------------------------------------------------------------------- the camera side
class Offer:
    """Keeps at most ``window`` frames in flight; a frame's answer frees its place."""

    def __init__(self, window: int) -> None:
        self.places = threading.Semaphore(window)
        self.answered: dict[int, int] = {}

    def answer(self, stamp: int) -> None:
        self.answered[stamp] = time.time_ns()
        self.places.release()


def offer_frames(send: Callable[[int, int], None], offer: Offer, count: int) -> Run:
    """Send ``count`` frames as soon as the window allows (the first ``window`` back to back);
    latency and throughput from the answers."""
    sent: list[int] = []
    for index in range(count):
        offer.places.acquire(timeout=WAIT)  # on a timeout the lost frame's place is reused
        stamp = time.time_ns()
        sent.append(stamp)
        send(stamp, index)
    deadline = time.monotonic() + WAIT
    while not all(stamp in offer.answered for stamp in sent) and time.monotonic() < deadline:
        time.sleep(0.002)
    answered = [stamp for stamp in sent if stamp in offer.answered]
    answers = sorted(offer.answered[stamp] for stamp in answered)
    run = Run("", frames=len(answered), lost=count - len(answered))
    run.latency = [(offer.answered[stamp] - stamp) / 1e6 for stamp in answered]
    if len(answers) > 1:
        run.fps_rounds = [(len(answers) - 1) / ((answers[-1] - answers[0]) / 1e9)]
    return run


def stages_of(records: Sequence[dict[str, float]], run: Run) -> Run:
    run.stages = {stage: [record[stage] for record in records if stage in record]
                  for stage in STAGES}
    run.detections = [record["detections"] for record in records]
    return run
