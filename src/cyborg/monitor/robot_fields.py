"""The fields of the robot commands a page sends, checked before anything reaches the bus.

A robot command (:mod:`cyborg.monitor.robot_commands`) carries numbers (``vx``, ``wz``),
poses (``[x, y]`` or ``[x, y, θ]``, metres and radians, in the map frame) and a tour's list of
poses. JSON cannot carry NaN or infinities to the monitor (:func:`~cyborg.monitor.limits.decode`
refuses them), but anything else can come: a string, a boolean, a list of the wrong length, a
point far off any map. Each check here raises :class:`RefusalError` naming the field at
fault and what it holds, which the page shows as the command's refusal.
"""

from __future__ import annotations

import math
from typing import Any

from cyborg.monitor.refusal import RefusalError
from cyborg.monitor.robot_wire import WORLD_LIMIT
from cyborg.monitor.tour import TOUR_LIMIT, Waypoint


def short(value: Any) -> str:
    """A field's value for an error message, at most 60 characters."""
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


ANGLE_LIMIT = 10 * math.tau
"""Largest heading a pose may give, in radians either way; past a full turn it is taken
modulo one."""


def _finite(value: Any) -> bool:
    """A number that fits a float and is finite (a 400-digit integer does not fit)."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        return False
    try:
        return math.isfinite(float(value))
    except OverflowError:
        return False


def number_field(command: dict[str, Any], field: str) -> float:
    """``command[field]`` as a finite float; :class:`RefusalError` naming it otherwise."""
    value: Any = command.get(field)
    if not _finite(value):
        raise RefusalError(f"{field} is {short(value)}, not a finite number", field)
    return float(value)


def pose_field(command: dict[str, Any], field: str) -> tuple[float, float, float | None]:
    """``command[field]``, ``[x, y]`` or ``[x, y, θ]`` (m, rad): x, y and θ or None.

    Refused unless every number is finite and x and y lie within
    :data:`~cyborg.monitor.robot_wire.WORLD_LIMIT` of the map's origin.
    """
    return _pose(command.get(field), field)


def _pose(value: Any, field: str) -> tuple[float, float, float | None]:
    if not isinstance(value, list) or len(value) not in (2, 3):
        raise RefusalError(f"{field}: [x, y] or [x, y, θ] in metres and radians, not "
                                f"{short(value)}", field)
    for index, item in enumerate(value):
        if not _finite(item):
            raise RefusalError(f"{field}[{index}] is {short(item)}, not a finite number",
                                    field)
    numbers = [float(item) for item in value]
    if max(abs(numbers[0]), abs(numbers[1])) > WORLD_LIMIT:
        raise RefusalError(f"{field}: {short(value)} is more than {WORLD_LIMIT / 1000:g} km "
                                "from the map's origin", field)
    if len(numbers) == 2:
        return numbers[0], numbers[1], None
    if abs(numbers[2]) > ANGLE_LIMIT:
        raise RefusalError(f"{field}[2] is {short(value[2])}, not a heading in radians "
                                f"(at most {ANGLE_LIMIT:.1f} either way)", field)
    heading = numbers[2]
    return numbers[0], numbers[1], heading if abs(heading) <= math.tau else math.remainder(
        heading, math.tau)


def tour_points(command: dict[str, Any]) -> list[Waypoint]:
    """The ``points`` of a ``tour`` command: 1 to :data:`~cyborg.monitor.tour.TOUR_LIMIT` poses."""
    points = command.get("points")
    if not isinstance(points, list) or not 1 <= len(points) <= TOUR_LIMIT:
        raise RefusalError(f"points: a list of 1 to {TOUR_LIMIT} [x, y] or [x, y, θ], "
                                f"not {short(points)}", "points")
    return [_pose(point, f"points[{index}]") for index, point in enumerate(points)]
