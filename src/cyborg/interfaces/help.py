"""A robot's call for help on the bus: who calls, where it stands, and why.

A robot that has stopped and cannot go on by itself (the bundled mission's critical mode,
docs/modes.md) says so on ``help`` under the robot's namespace (``/cyborg/help`` by default),
a ``std_msgs/String`` holding one JSON object, so that any tool — ``cyborg topic echo``, a
monitor, a phone bridge — reads it without a message package of its own:

=============  =========================================================================
field          meaning
=============  =========================================================================
``schema``     :data:`SCHEMA`, ``cyborg.help/1``
``robot``      the robot's namespace (``/cyborg``, ``/robot2``)
``reason``     why it calls, in words
``pose``       ``{"x", "y", "theta"}`` on the map (metres, radians), or null when unknown
``battery``    the charge in percent, or null when unknown
``time``       when it called, in seconds of the robot's clock
=============  =========================================================================

The robot's side writes a call with :func:`help_text`; whoever listens reads it with
:func:`read_help`, which names the field at fault in a text that is not a call.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from typing import Any

from cyborg.bus.msgs.std_msgs.msg import String
from cyborg.interfaces.contract import Topic

SCHEMA = "cyborg.help/1"
"""The ``schema`` of a call for help."""

HELP = Topic("help", String)
"""Calls for help, under the robot's namespace: not latched, a call is news once."""
TOPICS: tuple[Topic, ...] = (HELP,)


@dataclass(frozen=True)
class HelpCall:
    """One call for help, as :data:`HELP` carries it."""

    robot: str
    reason: str
    pose: tuple[float, float, float] | None
    """``(x, y, theta)`` on the map, or None when the robot does not know where it is."""
    battery: float | None
    time: float

    def to_json(self) -> dict[str, Any]:
        """The JSON object of the call (see the module docstring)."""
        pose = None if self.pose is None else dict(zip(("x", "y", "theta"), self.pose,
                                                       strict=True))
        return {"schema": SCHEMA, "robot": self.robot, "reason": self.reason, "pose": pose,
                "battery": self.battery, "time": self.time}


def help_text(call: HelpCall) -> String:
    """The message that carries ``call``."""
    return String(data=json.dumps(call.to_json(), separators=(",", ":")))


def read_help(message: String) -> HelpCall:
    """The call a message carries; ValueError naming the field when it is not one."""
    try:
        data = json.loads(message.data)
    except json.JSONDecodeError as exc:
        raise ValueError(f"a call for help is one JSON object: {exc}") from exc
    if not isinstance(data, dict):
        raise ValueError("a call for help is one JSON object, not "
                         f"{type(data).__name__}")
    if data.get("schema") != SCHEMA:
        raise ValueError(f"schema: expected {SCHEMA!r}, got {data.get('schema')!r}")
    for key in ("robot", "reason"):
        if not isinstance(data.get(key), str):
            raise ValueError(f"{key}: expected a string, got {data.get(key)!r}")
    pose = data.get("pose")
    if pose is not None:
        if not isinstance(pose, dict) or not all(_number(pose.get(k)) for k in "xy"):
            raise ValueError(f"pose: expected {{'x', 'y', 'theta'}} in numbers, got {pose!r}")
        pose = (float(pose["x"]), float(pose["y"]), float(pose.get("theta") or 0.0))
    battery = data.get("battery")
    if battery is not None and not _number(battery):
        raise ValueError(f"battery: expected a number or null, got {battery!r}")
    if not _number(data.get("time")):
        raise ValueError(f"time: expected a number, got {data.get('time')!r}")
    return HelpCall(data["robot"], data["reason"], pose,
                    None if battery is None else float(battery), float(data["time"]))


def _number(value: object) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool) and \
        math.isfinite(value)
