"""What the objects of an ARNL map (``Cairn:`` lines) mean for navigation.

====================  ===================================================================
kind                  meaning
====================  ===================================================================
``Goal``              a named point; its heading is ignored
``GoalWithHeading``   a named pose; the robot turns to the heading on arrival
``Dock``              where docking starts (a pose; custom dock types from ``MapInfo``)
``RobotHome``         a start pose, or a start area when it has a region
``ForbiddenLine``     a line the robot must not cross (the region's two endpoints)
``ForbiddenArea``     a rectangle the robot must not enter, rotated about the map origin
``Sim.BoxObstacle``   a box that only the simulator puts into the world
====================  ===================================================================

Types declared by ``MapInfo:`` lines extend these: a ``GoalType`` is a goal, a ``DockType`` a
dock. Other sectors and boundaries (labels, reflectors, measuring sticks, slow zones) are kept
but do not block the robot; only the ``Forbidden*`` kinds do. Sectors named ``Sim.*`` are
simulator obstacles.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, replace

import numpy as np

GOAL, GOAL_WITH_HEADING, DOCK, HOME = "goal", "goal_with_heading", "dock", "home"
FORBIDDEN_LINE, FORBIDDEN_AREA, SIM_OBSTACLE, OTHER = (
    "forbidden_line", "forbidden_area", "sim_obstacle", "other")


@dataclass(frozen=True)
class MapType:
    """A ``MapInfo:`` declaration, e.g. ``GoalType`` named ``Goal`` or ``DockPioneer``."""

    category: str  # GoalType, DockType, SectorType, BoundaryType, LocationType, ArgDesc, ...
    settings: dict[str, str]
    line: int

    @property
    def name(self) -> str:
        """The declared type's name (its ``Name=`` setting); empty if it has none."""
        return self.settings.get("Name", "")


@dataclass(frozen=True)
class MapObject:
    """A cairn, in metres and radians. ``region`` is ``(from_x, from_y, to_x, to_y)``.

    ``kind`` is the word after ``Cairn:``, ``line`` the line in the file, and ``category`` what
    the object means for navigation (see :meth:`classified`).
    """

    kind: str
    x: float
    y: float
    theta: float
    description: str
    icon: str
    name: str
    region: tuple[float, float, float, float] | None
    line: int
    category: str = OTHER

    # ------------------------------------------------------------------ kinds
    @property
    def is_goal(self) -> bool:
        """Whether it is a goal, with or without heading (a dock is not)."""
        return self.category in (GOAL, GOAL_WITH_HEADING)

    @property
    def is_dock(self) -> bool:
        """Whether it is a dock: ``Dock`` or a kind declared as a ``DockType``."""
        return self.category == DOCK

    @property
    def has_heading(self) -> bool:
        """Whether arriving here means turning to ``theta`` (goals with heading and docks)."""
        return self.category in (GOAL_WITH_HEADING, DOCK)

    @property
    def is_forbidden_line(self) -> bool:
        """Whether it is a ``ForbiddenLine``, a line the robot must not cross."""
        return self.category == FORBIDDEN_LINE

    @property
    def is_forbidden_area(self) -> bool:
        """Whether it is a ``ForbiddenArea``, a rectangle the robot must not enter."""
        return self.category == FORBIDDEN_AREA

    @property
    def is_sim_obstacle(self) -> bool:
        """Whether it is a box that only the simulator puts into the world (``Sim.*``)."""
        return self.category == SIM_OBSTACLE

    def classified(self, declared: Mapping[str, str]) -> MapObject:
        """This object with its category, given the map's ``MapInfo`` declarations.

        ``declared`` is what :func:`declared_categories` returns, built once per map rather
        than once per object.
        """
        return replace(self, category=_category(self.kind, self.region is not None, declared))

    # ------------------------------------------------------------------ geometry
    def corners(self) -> np.ndarray | None:
        """The region's outline in metres, as an (N, 2) array; None without a region.

        That is the two endpoints of a line, or the four corners of an area (rotated by
        ``theta`` about the map origin, as ARIA does).
        """
        if self.region is None:
            return None
        fx, fy, tx, ty = self.region
        if self.category == FORBIDDEN_LINE:
            return np.array([[fx, fy], [tx, ty]])
        cos, sin = math.cos(self.theta), math.sin(self.theta)
        square = np.array([[fx, fy], [tx, fy], [tx, ty], [fx, ty]])
        rotation = np.array([[cos, -sin], [sin, cos]])
        rotated: np.ndarray = square @ rotation.T
        return rotated

    def contains(self, x: float, y: float) -> bool:
        """Whether the point lies inside this object's area (False for lines and points)."""
        corners = self.corners()
        if corners is None or len(corners) != 4:
            return False
        cos, sin = math.cos(-self.theta), math.sin(-self.theta)
        ux, uy = x * cos - y * sin, x * sin + y * cos  # undo the rotation
        assert self.region is not None
        fx, fy, tx, ty = self.region
        return min(fx, tx) <= ux <= max(fx, tx) and min(fy, ty) <= uy <= max(fy, ty)


def declared_categories(types: Iterable[MapType]) -> dict[str, str]:
    """Declared type name → category (``GoalType``, ``DockType`` ...).

    A later declaration of the same name wins.
    """
    return {declaration.name: declaration.category for declaration in types}


def _category(kind: str, has_region: bool, declared: Mapping[str, str]) -> str:
    if kind == "Goal":
        return GOAL
    if kind == "GoalWithHeading":
        return GOAL_WITH_HEADING
    if kind == "Dock":
        return DOCK
    if kind == "RobotHome":
        return HOME
    if kind == "ForbiddenLine":
        return FORBIDDEN_LINE
    if kind == "ForbiddenArea":
        return FORBIDDEN_AREA
    if kind.startswith("Sim.") and has_region:
        return SIM_OBSTACLE
    category = declared.get(kind)
    if category == "DockType":
        return DOCK
    if category == "GoalType":
        return GOAL_WITH_HEADING if kind.endswith("WithHeading") else GOAL
    return OTHER
