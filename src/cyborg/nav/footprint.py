"""The robot's shape as navigation needs it: footprint, clearance radii, body circles.

Figures for the Pioneer LX come from MobileSim's robot model: a 0.64 x 0.48 m body. The planner
keeps the path's cells at least the *circumscribed* radius from walls (so turning anywhere on
the path is safe); a pose counts as "inside a wall" when even the *inscribed* radius collides.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Footprint:
    """A rectangular robot body with cut corners, centred on the drive axle.

    ``length`` (along x) and ``width`` are in metres; each corner is cut ``corner_cut`` metres
    along both sides.
    """

    length: float
    width: float
    corner_cut: float = 0.06

    @property
    def inscribed_radius(self) -> float:
        """Half the width, in m: the largest circle about the axle inside the body."""
        return self.width / 2

    @property
    def circumscribed_radius(self) -> float:
        """Half the diagonal, in m: the smallest circle about the axle around the body."""
        return math.hypot(self.length / 2, self.width / 2)

    def polygon(self) -> np.ndarray:
        """The outline as a 12-point polygon in the robot frame (x forward, y left)."""
        hx, hy, cut = self.length / 2, self.width / 2, self.corner_cut
        outline = []
        for sx, sy in ((1, 1), (-1, 1), (-1, -1), (1, -1)):
            corner = [(sx * hx, sy * (hy - cut)), (sx * (hx - cut / 2), sy * (hy - cut / 2)),
                      (sx * (hx - cut), sy * hy)]
            outline.extend(corner if sx * sy > 0 else corner[::-1])
        return np.array(outline)

    def circles(self) -> tuple[np.ndarray, float]:
        """Centres (along x) and radius of circles covering the body, for collision checks."""
        radius = self.width / 2
        reach = self.length / 2 - radius
        return np.array([-reach, 0.0, reach]), radius


PIONEER_LX = Footprint(length=0.64, width=0.48)
