"""A robot's map as ``foxglove.SceneUpdate`` lines and labels, drawn by the 3D panel as they are.

:func:`map_scene` turns a ``cyborg_msgs/msg/MapGeometry`` into one scene update in the map's
frame (``map``) that first deletes what an earlier map drew, then draws, as entities:

==================  ======================================================================
entity id           what
==================  ======================================================================
``map/walls``       the wall lines, dark grey, 5 cm wide
``map/forbidden``   forbidden lines and the edges of forbidden areas, red
``map/goals``       every named object (goal, dock, home): an arrow where the object has a
                    heading (a goal with heading, a dock, a home), a sphere where it has
                    none, and its name above it, facing the viewer
==================  ======================================================================

Scanned points are left to the occupancy grid (:mod:`cyborg.foxglove.map_grid`): a map holds
tens of thousands of them. Coordinates that are not finite are left out.
"""

from __future__ import annotations

import math

import numpy as np
from foxglove.messages import (
    ArrowPrimitive,
    Color,
    LinePrimitive,
    LinePrimitiveLineType,
    Point3,
    Pose,
    Quaternion,
    SceneEntity,
    SceneEntityDeletion,
    SceneEntityDeletionType,
    SceneUpdate,
    SpherePrimitive,
    TextPrimitive,
    Timestamp,
    Vector3,
)

from cyborg.bus.msgs.cyborg_msgs.msg import MapGeometry, MapObject

WALLS = "map/walls"
FORBIDDEN = "map/forbidden"
GOALS = "map/goals"
WALL_COLOR = Color(r=0.2, g=0.2, b=0.2, a=1.0)
FORBIDDEN_COLOR = Color(r=0.9, g=0.1, b=0.1, a=1.0)
GOAL_COLOR = Color(r=0.1, g=0.5, b=0.9, a=1.0)
DOCK_COLOR = Color(r=0.1, g=0.7, b=0.2, a=1.0)
LABEL_COLOR = Color(r=1.0, g=1.0, b=1.0, a=1.0)
LINE_WIDTH = 0.05
"""Metres: how wide walls and forbidden lines are drawn."""
NAMED = {MapObject.GOAL, MapObject.GOAL_WITH_HEADING, MapObject.DOCK, MapObject.HOME}
"""The categories drawn as named places."""
WITH_HEADING = {MapObject.GOAL_WITH_HEADING, MapObject.DOCK, MapObject.HOME}
"""The categories whose heading matters: drawn as arrows."""


def map_scene(message: MapGeometry) -> SceneUpdate:
    """The scene update that draws the map of ``message`` (see the module's description)."""
    stamp = Timestamp(int(message.header.stamp.sec), int(message.header.stamp.nanosec))
    frame = message.header.frame_id
    walls = _lines(np.asarray(message.lines, np.float64).reshape(-1, 4)
                   if len(message.lines) % 4 == 0 else np.zeros((0, 4)))
    forbidden: list[Point3] = []
    arrows: list[ArrowPrimitive] = []
    spheres: list[SpherePrimitive] = []
    texts: list[TextPrimitive] = []
    for item in message.objects:
        outline = np.asarray(item.outline, np.float64)
        outline = outline[:len(outline) // 2 * 2].reshape(-1, 2)
        if item.category == MapObject.FORBIDDEN_LINE and len(outline) == 2:
            forbidden += _lines(outline.reshape(1, 4))
        elif item.category == MapObject.FORBIDDEN_AREA and len(outline) >= 3:
            forbidden += _lines(np.hstack([outline, np.roll(outline, -1, axis=0)]))
        elif item.category in NAMED:
            _place(item, arrows, spheres, texts)
    return SceneUpdate(
        deletions=[SceneEntityDeletion(timestamp=stamp, type=SceneEntityDeletionType.All)],
        entities=[
            SceneEntity(timestamp=stamp, frame_id=frame, id=WALLS,
                        lines=[_line_list(walls, WALL_COLOR)]),
            SceneEntity(timestamp=stamp, frame_id=frame, id=FORBIDDEN,
                        lines=[_line_list(forbidden, FORBIDDEN_COLOR)]),
            SceneEntity(timestamp=stamp, frame_id=frame, id=GOALS, arrows=arrows,
                        spheres=spheres, texts=texts)])


def _lines(segments: np.ndarray) -> list[Point3]:
    """The ends of ``x1 y1 x2 y2`` rows as points of a line list, non-finite rows left out."""
    kept = segments[np.isfinite(segments).all(axis=1)]
    return [Point3(x=float(x), y=float(y), z=0.0) for x, y in kept.reshape(-1, 2)]


def _line_list(points: list[Point3], color: Color) -> LinePrimitive:
    return LinePrimitive(type=LinePrimitiveLineType.LineList, thickness=LINE_WIDTH,
                         points=points, color=color)


def _place(item: MapObject, arrows: list[ArrowPrimitive], spheres: list[SpherePrimitive],
           texts: list[TextPrimitive]) -> None:
    """Draw one named object: an arrow or a sphere, and its name above it."""
    x, y, theta = float(item.pose.x), float(item.pose.y), float(item.pose.theta)
    if not (math.isfinite(x) and math.isfinite(y)):
        return
    color = DOCK_COLOR if item.category == MapObject.DOCK else GOAL_COLOR
    if item.category in WITH_HEADING and math.isfinite(theta):
        heading = Quaternion(x=0.0, y=0.0, z=math.sin(theta / 2), w=math.cos(theta / 2))
        arrows.append(ArrowPrimitive(
            pose=Pose(position=Vector3(x=x, y=y, z=0.05), orientation=heading),
            shaft_length=0.35, shaft_diameter=0.06, head_length=0.2, head_diameter=0.16,
            color=color))
    else:
        spheres.append(SpherePrimitive(
            pose=Pose(position=Vector3(x=x, y=y, z=0.1),
                      orientation=Quaternion(x=0.0, y=0.0, z=0.0, w=1.0)),
            size=Vector3(x=0.2, y=0.2, z=0.2), color=color))
    if item.name:
        texts.append(TextPrimitive(
            pose=Pose(position=Vector3(x=x, y=y, z=0.5),
                      orientation=Quaternion(x=0.0, y=0.0, z=0.0, w=1.0)),
            billboard=True, font_size=14.0, scale_invariant=True, color=LABEL_COLOR,
            text=item.name))
