"""What the simulated camera can see: walking people and objects placed on the map.

A :class:`Sights` is a set of round things standing on the floor, each with a label (the
class the real detector would give it), a position (m, map frame), a radius and a height
(m). The camera (:mod:`cyborg.sim.camera`) detects them.

* People (:func:`crowd_sights`) are ``person`` (:data:`cyborg.interfaces.simulation.
  PERSON_LABEL`), as tall and as round as their crowd's settings.
* Objects are point objects of kind ``Sim.Object`` on the map (:func:`placed_objects`): the
  description gives the label, then optionally the height and radius in metres (defaults
  :data:`OBJECT_HEIGHT`, :data:`OBJECT_RADIUS`); the name is free. They stand still and only
  the camera sees them (to block the laser and the robot as well, put a ``Sim.BoxObstacle``
  around them)::

      Cairn: Sim.Object 3000 1500 0 "chair 0.9 0.3" ICON "chair1"
      Cairn: Sim.Object 8000 2500 0 "potted plant" ICON "plant"
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import NamedTuple

import numpy as np

from cyborg.interfaces.simulation import PERSON_LABEL
from cyborg.nav.arnl_map import ArnlMap, MapError
from cyborg.sim.people import Crowd

OBJECT_KIND = "Sim.Object"
"""The map object kind of a thing the simulated camera can see."""
OBJECT_HEIGHT = 0.8
"""Metres tall, for a ``Sim.Object`` whose description gives no height."""
OBJECT_RADIUS = 0.25
"""Metres of radius, for a ``Sim.Object`` whose description gives none."""


class Sights(NamedTuple):
    """Things the camera may see: labels, positions ((N, 2), m), radii and heights (m)."""

    labels: tuple[str, ...]
    positions: np.ndarray
    radii: np.ndarray
    heights: np.ndarray

    @staticmethod
    def none() -> Sights:
        """Nothing to see."""
        return Sights((), np.zeros((0, 2)), np.zeros(0), np.zeros(0))

    def joined(self, other: Sights) -> Sights:
        """These things and ``other``'s."""
        return Sights(self.labels + other.labels,
                      np.concatenate([self.positions, other.positions]),
                      np.concatenate([self.radii, other.radii]),
                      np.concatenate([self.heights, other.heights]))


def crowd_sights(crowd: Crowd | None) -> Sights:
    """The crowd's people where they are now (none without a crowd)."""
    if crowd is None or not len(crowd):
        return Sights.none()
    count, settings = len(crowd), crowd.settings
    return Sights((PERSON_LABEL,) * count, crowd.positions, np.full(count, settings.radius),
                  np.full(count, settings.height))


def placed_objects(arnl_map: ArnlMap) -> Sights:
    """The map's ``Sim.Object`` objects; MapError naming the line of one without a label."""
    labels: list[str] = []
    rows: list[Sequence[float]] = []
    for item in arnl_map.objects:
        if item.kind != OBJECT_KIND or item.region is not None:
            continue
        words = item.description.split()
        numbers: list[float] = []
        while words and _number(words[-1]) is not None and len(numbers) < 2:
            numbers.insert(0, float(words.pop()))
        if not words:
            raise MapError(arnl_map.source, item.line,
                           f"{OBJECT_KIND} {item.name!r}: the description {item.description!r} "
                           "names no label (a class such as 'chair', then optionally its "
                           "height and radius in metres)")
        height = numbers[0] if numbers else OBJECT_HEIGHT
        radius = numbers[1] if len(numbers) > 1 else OBJECT_RADIUS
        if height <= 0 or radius <= 0:
            raise MapError(arnl_map.source, item.line,
                           f"{OBJECT_KIND} {item.name!r}: height and radius must be positive, "
                           f"not {height:g} and {radius:g}")
        labels.append(" ".join(words))
        rows.append((item.x, item.y, radius, height))
    if not rows:
        return Sights.none()
    table = np.array(rows, dtype=np.float64)
    return Sights(tuple(labels), table[:, :2], table[:, 2], table[:, 3])


def _number(word: str) -> float | None:
    try:
        return float(word)
    except ValueError:
        return None
