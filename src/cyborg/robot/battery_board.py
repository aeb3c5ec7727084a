"""``ReadBattery{key}``: the robot's battery into the blackboard, for conditions to read.

A mode file's conditions (``battery.percent < 30``, docs/modes.md) and behavior3 1.x ``Check``
nodes read plain blackboard keys. Put ``ReadBattery`` first under a tree's root ``Sequence``
and each tick writes the last battery reading to the **global** scope, shared by every mode's
tree:

* ``<key>`` (default ``battery``): ``{"percent", "charging", "docked", "dock_state", "time"}``
  — the charge in percent, whether the charger is on, whether the robot is docked, the dock
  state in lower case (``undocked``, ``docking``, ...) and the reading's stamp;
* ``<key>_percent``: the charge alone, for nodes that compare one key.

It always succeeds; before the robot's first reading it writes nothing (and a condition on
``battery.percent`` is false, as docs/modes.md says of a missing key). The entries have the
shape the ``BatteryWatch`` service on a composite writes, so a tree may swap one for the
other without touching what reads them.
"""

from __future__ import annotations

from typing import Any

from typing_extensions import override

from cyborg.bt import SUCCESS, Action, Status, register
from cyborg.robot.protocol import ROBOT, BatteryReading, DockState, robot_of


def battery_entry(reading: BatteryReading) -> dict[str, Any]:
    """The blackboard entry of a reading: ``{"percent", "charging", "docked", ...}``."""
    return {"percent": reading.charge_percent, "charging": reading.charging,
            "docked": reading.dock_state is DockState.DOCKED,
            "dock_state": reading.dock_state.name.lower(), "time": reading.time}


@register
class ReadBattery(Action):
    """Write the last battery reading to the global blackboard; always SUCCESS."""

    requires = (ROBOT,)

    def __init__(self, key: str = "battery") -> None:
        if not key:
            raise ValueError("key is empty: name the blackboard entry to write")
        self.key = key

    @override
    def tick(self) -> Status:
        reading = robot_of(self).battery
        if reading is not None:
            self.blackboard[self.key] = battery_entry(reading)
            self.blackboard[f"{self.key}_percent"] = reading.charge_percent
        return SUCCESS
