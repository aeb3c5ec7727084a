"""Tracking: sightings of one label near one place, frame after frame, become one object.

:class:`Tracker` keeps the objects a robot has seen on the map. Each frame of
:class:`~cyborg.perception.sighting.Sighting` s (detections already placed on the map) goes
through :meth:`Tracker.update`:

* **prediction** — each object is moved along its velocity to the frame's stamp (at most
  :attr:`TrackerSettings.horizon` seconds ahead, so an old guess does not wander off);
* **gating and association**, per label — a sighting may only join an object of its own label
  whose predicted position, or the position where it was last seen (someone who stopped or
  turned back while unseen), lies within the pair's gate: :attr:`TrackerSettings.gate`
  metres, widened by :attr:`TrackerSettings.spread` metres for each second the object has
  been unseen (up to the horizon: a person hidden behind a pillar or another person for a
  second may be a metre and a half from where they were guessed to be) and by
  :attr:`TrackerSettings.depth_sigmas` standard deviations of the sighting's depth error (a
  stereo camera's depth of a person 15 m away jumps by a metre from frame to frame:
  :meth:`~cyborg.interfaces.perception.CameraModel.depth_sigma`). The pairs within their gate
  are taken greedily, nearest first, each object and sighting at most once (a greedy
  assignment: with objects further apart than the gate, as people are, it gives what an
  optimal one would). So a person keeps their track through missed frames, a turn, or a few
  seconds hidden; one unseen for :attr:`TrackerSettings.forget_after` seconds is forgotten and
  gets a new id when seen again (the tracker compares places, not looks);
* **update** — a joined object follows its sighting with an alpha-beta filter (a small
  constant-velocity filter): position ``p = p' + alpha * r`` and velocity
  ``v = v + beta * r / dt``, where ``p'`` is the prediction, ``r`` the sighting's offset from
  it and ``dt`` the time since the object was last seen; speeds are capped at
  :attr:`TrackerSettings.max_speed`. The longer an object was unseen, the more its sighting is
  believed: ``alpha`` is at least the share of the gate that the time unseen added. An object
  found beyond the plain gate from its prediction but nearer where it was last seen stopped or
  turned while unseen: it goes on from there, at rest (a stale velocity would carry it off).
  A sighting no object takes starts a new object (its own id, at rest);
* **confidence** — each sighting raises it, ``c = 1 - (1 - c) * (1 - g * s)`` (``s`` the
  detection's score, ``g`` :attr:`TrackerSettings.gain`), so an object seen often is trusted
  more than one seen once; unseen, it halves every :attr:`TrackerSettings.half_life` seconds
  (:meth:`TrackedObject.confidence_at`);
* **forgetting** — an object unseen for :attr:`TrackerSettings.forget_after` seconds is
  dropped; so is the least confident when more than :attr:`TrackerSettings.max_objects` are
  kept. A stamp more than that long before the newest (a restarted simulation) starts afresh.

Time is whatever the stamps say (simulated seconds under ``use_sim_time``): the tracker reads
no clock and does no I/O. :func:`track_frames` runs it over a list of frames, as a benchmark or
an accuracy test does.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field

import numpy as np

from cyborg.interfaces.perception import ASSOCIATION_GATE, CAMERA, FORGET_AFTER, CameraModel
from cyborg.perception.sighting import Detection, RobotPose, Sighting, locate


@dataclass(frozen=True)
class TrackerSettings:
    """How the tracker joins, smooths, trusts and forgets (see the module docstring)."""

    gate: float = ASSOCIATION_GATE
    """Metres: the furthest a sighting may lie from an object's prediction to join it, when
    the object was seen in the frame before and the sighting is near (see the next two)."""
    spread: float = 1.5
    """Metres per second: how much the gate widens for each second an object is unseen (up
    to ``horizon``), as far as a person walking briskly may stray from the guess meanwhile."""
    depth_sigmas: float = 3.0
    """How many standard deviations of a sighting's depth error (``camera``'s
    :meth:`~cyborg.interfaces.perception.CameraModel.depth_sigma` at its distance) widen the
    gate, so that the noise of a far sighting does not start a new object."""
    camera: CameraModel = CAMERA
    """The camera the sightings come from, for its depth noise."""
    forget_after: float = FORGET_AFTER
    """Seconds unseen after which an object is dropped."""
    alpha: float = 0.4
    """Share of a sighting's offset the position follows (0..1)."""
    beta: float = 0.05
    """Share of a sighting's offset, per second, the velocity follows (0..1). With ``alpha``,
    chosen for 5 to 15 frames a second and 0.1 m of noise: a person standing still reads
    about 0.1 m/s (99th percentile 0.3), one walking at 1 m/s is within 0.2 m/s of it after
    3 s."""
    max_speed: float = 3.0
    """Metres per second an object's velocity is capped at."""
    horizon: float = 2.0
    """Seconds an object's position is predicted ahead at most."""
    gain: float = 0.5
    """How much one sighting of score 1 closes the gap to full confidence (0..1)."""
    half_life: float = 1.0
    """Seconds in which an unseen object's confidence halves."""
    max_objects: int = 256
    """Objects kept at most; the least confident go first."""

    def __post_init__(self) -> None:
        """Refuses settings that make no tracker, naming the field."""
        for name in ("gate", "forget_after", "max_speed", "horizon", "half_life"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"tracker setting {name} must be a positive number, not {value}")
        for name in ("spread", "depth_sigmas"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0):
                raise ValueError(f"tracker setting {name} must be 0 or more, not {value}")
        for name in ("alpha", "beta", "gain"):
            value = getattr(self, name)
            if not 0.0 < value <= 1.0:
                raise ValueError(f"tracker setting {name} must lie in (0, 1], not {value}")
        if self.max_objects < 1:
            raise ValueError(f"tracker setting max_objects must be at least 1, not "
                             f"{self.max_objects}")


@dataclass
class TrackedObject:
    """One object the tracker follows: where it is, how it moves, how far it is trusted."""

    id: int
    label: str
    x: float
    """Metres on the map, where it was last seen (filtered)."""
    y: float
    vx: float = 0.0
    """Metres per second on the map."""
    vy: float = 0.0
    last_seen: float = 0.0
    """Stamp of its last sighting, seconds."""
    times_seen: int = 1
    confidence: float = 0.0
    """0..1 as of ``last_seen``; see :meth:`confidence_at`."""
    distance: float = math.nan
    """Metres from the robot's centre at its last sighting."""
    bearing: float = math.nan
    """Radians from the robot's heading at its last sighting, positive left."""
    half_life: float = field(default=1.0, repr=False)

    def confidence_at(self, now: float) -> float:
        """The confidence at ``now``: halved every ``half_life`` seconds since last seen."""
        age = max(0.0, now - self.last_seen)
        return float(self.confidence * 0.5 ** (age / self.half_life))

    def predicted(self, now: float, horizon: float = math.inf) -> tuple[float, float]:
        """Where it should be at ``now`` if it kept its velocity (for at most ``horizon`` s)."""
        dt = min(max(0.0, now - self.last_seen), horizon)
        return self.x + self.vx * dt, self.y + self.vy * dt


class Tracker:
    """The objects seen on the map, updated frame by frame (see the module docstring)."""

    def __init__(self, settings: TrackerSettings | None = None) -> None:
        self.settings = settings or TrackerSettings()
        self._objects: dict[int, TrackedObject] = {}
        self._next_id = 1
        self.newest = -math.inf
        """The newest stamp seen, seconds."""

    def __len__(self) -> int:
        return len(self._objects)

    def update(self, stamp: float, sightings: Iterable[Sighting]) -> None:
        """Take one frame's sightings, made at ``stamp`` (seconds)."""
        if not math.isfinite(stamp):
            raise ValueError(f"a frame's stamp must be a finite number of seconds, not {stamp}")
        if stamp < self.newest - self.settings.forget_after:
            self.clear()  # time went back: a restarted simulation or a replay from the start
        self.newest = max(self.newest, stamp)
        by_label: dict[str, list[Sighting]] = {}
        for sighting in sightings:
            by_label.setdefault(sighting.label, []).append(sighting)
        for label, group in by_label.items():
            self._associate(stamp, label, group)
        self.forget(self.newest)

    def _associate(self, stamp: float, label: str, sightings: list[Sighting]) -> None:
        candidates = [item for item in self._objects.values() if item.label == label]
        taken: set[int] = set()
        if candidates:
            settings = self.settings
            predicted = np.array([item.predicted(stamp, settings.horizon) for item in candidates])
            last = np.array([(item.x, item.y, item.last_seen) for item in candidates])
            seen = np.array([(sighting.x, sighting.y, sighting.distance)
                             for sighting in sightings])
            gaps = np.minimum(  # to the prediction, or to where it was (it stopped, turned)
                np.hypot(seen[:, None, 0] - predicted[None, :, 0],
                         seen[:, None, 1] - predicted[None, :, 1]),
                np.hypot(seen[:, None, 0] - last[None, :, 0], seen[:, None, 1] - last[None, :, 1]))
            rows, cols = np.nonzero(gaps <= self._gates(stamp, last[:, 2], seen[:, 2]))
            used: set[int] = set()
            for index in np.argsort(gaps[rows, cols], kind="stable"):
                row, col = int(rows[index]), int(cols[index])
                if row in taken or col in used:
                    continue
                taken.add(row)
                used.add(col)
                self._follow(candidates[col], sightings[row], stamp)
        for row, sighting in enumerate(sightings):
            if row not in taken:
                self._start(sighting, stamp)

    def _gates(self, stamp: float, last_seen: np.ndarray, distances: np.ndarray) -> np.ndarray:
        """The gate (m) of each sighting (rows) and object (columns), per the module docstring.

        It is wider the longer the object is unseen (since ``last_seen``) and the further the
        sighting is (its ``distances``).
        """
        settings = self.settings
        unseen = np.minimum(np.maximum(stamp - last_seen, 0.0), settings.horizon)
        noise = settings.depth_sigmas * settings.camera.depth_sigma(distances)  # screened: finite
        result: np.ndarray = (settings.gate + settings.spread * unseen)[None, :] + noise[:, None]
        return result

    def _follow(self, item: TrackedObject, sighting: Sighting, stamp: float) -> None:
        settings = self.settings
        dt = stamp - item.last_seen
        if dt > 0:
            px, py = item.predicted(stamp, settings.horizon)
            if math.hypot(sighting.x - px, sighting.y - py) > settings.gate and math.hypot(
                    sighting.x - item.x, sighting.y - item.y) < math.hypot(sighting.x - px,
                                                                           sighting.y - py):
                # it stopped or turned while unseen: go on from where it was, at rest
                px, py, item.vx, item.vy = item.x, item.y, 0.0, 0.0
            widened = settings.spread * min(dt, settings.horizon)
            alpha = max(settings.alpha, widened / (settings.gate + widened))
            rx, ry = sighting.x - px, sighting.y - py
            item.x, item.y = px + alpha * rx, py + alpha * ry
            vx = item.vx + settings.beta * rx / dt
            vy = item.vy + settings.beta * ry / dt
            speed = math.hypot(vx, vy)
            if speed > settings.max_speed:
                vx, vy = vx * settings.max_speed / speed, vy * settings.max_speed / speed
            item.vx, item.vy = vx, vy
            item.confidence = item.confidence_at(stamp)
            item.last_seen = stamp
        else:  # the same frame (or an older one): only the position is averaged
            item.x += settings.alpha * (sighting.x - item.x)
            item.y += settings.alpha * (sighting.y - item.y)
        item.confidence = 1.0 - (1.0 - item.confidence) * (1.0 - settings.gain
                                                            * sighting.confidence)
        item.times_seen += 1
        item.distance, item.bearing = sighting.distance, sighting.bearing

    def _start(self, sighting: Sighting, stamp: float) -> None:
        item = TrackedObject(self._next_id, sighting.label, sighting.x, sighting.y,
                             last_seen=stamp,
                             confidence=self.settings.gain * sighting.confidence,
                             distance=sighting.distance, bearing=sighting.bearing,
                             half_life=self.settings.half_life)
        self._next_id += 1
        self._objects[item.id] = item

    def forget(self, now: float) -> None:
        """Drop what is unseen for ``forget_after`` s at ``now``, and any beyond ``max_objects``.

        The least confident (at ``now``) go first when there are too many.
        """
        limit = now - self.settings.forget_after
        for key in [key for key, item in self._objects.items() if item.last_seen < limit]:
            del self._objects[key]
        excess = len(self._objects) - self.settings.max_objects
        if excess > 0:
            weakest = sorted(self._objects.values(), key=lambda item: item.confidence_at(now))
            for item in weakest[:excess]:
                del self._objects[item.id]

    def clear(self) -> None:
        """Forget everything (ids go on counting)."""
        self._objects.clear()
        self.newest = -math.inf

    def objects(self) -> list[TrackedObject]:
        """The objects followed, by id (the tracker's own: do not change them)."""
        return [self._objects[key] for key in sorted(self._objects)]


Frame = tuple[float, RobotPose, list[Detection]]
"""One camera frame: its stamp (seconds), the robot's pose then, and its detections."""


def track_frames(frames: Iterable[Frame], tracker: Tracker | None = None
                 ) -> Iterator[list[TrackedObject]]:
    """The objects after each frame, tracking ``frames`` in order with ``tracker`` (a new one).

    The detections must be screened already (:func:`cyborg.perception.screening.screen`); the
    camera is :data:`~cyborg.interfaces.perception.CAMERA` at its mount. The lists yielded are
    the tracker's objects as they are after that frame; copy what must outlive the next one.
    """
    tracker = tracker or Tracker()
    for stamp, pose, detections in frames:
        tracker.update(stamp, locate(detections, pose, CAMERA))
        yield tracker.objects()
