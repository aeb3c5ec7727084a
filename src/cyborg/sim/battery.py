"""The robot's battery: drains while the robot is on, faster when driving; charges when docked.

A model, not a measurement of the LX: a full battery lasts ``idle_hours`` standing still
(13 h by default); driving adds ``driving_drain`` percent per hour at 1 m/s; docked, the charger
fills ``charge_rate`` percent per hour, bulk charging to 80 %, then more slowly (overcharge
stage) to 100 %, then float. Charging states use rosarnl's numbers, as BatteryStatus.msg declares
them (:class:`cyborg.interfaces.robot.ChargingState`).
"""

from __future__ import annotations

from dataclasses import dataclass

from cyborg.interfaces.robot import ChargingState as ChargingState


@dataclass
class Battery:
    """The battery's charge, and how use and the charger change it (see the module doc).

    ``charge_percent`` runs from 0 to 100; the voltage is linear in it between ``empty_volts``
    and ``full_volts``; ``charging`` is set while the robot is docked and powered.
    """

    charge_percent: float = 100.0
    idle_hours: float = 13.0  # hours from full to empty standing still
    driving_drain: float = 2.0  # extra percent per hour per m/s
    charge_rate: float = 40.0  # percent per hour while bulk charging
    empty_volts: float = 22.0
    full_volts: float = 26.0
    charging: bool = False

    @property
    def voltage(self) -> float:
        """Volts, linear in the charge from ``empty_volts`` (0 %) to ``full_volts`` (100 %)."""
        return self.empty_volts + (self.full_volts - self.empty_volts) * self.charge_percent / 100

    @property
    def state(self) -> ChargingState:
        """Bulk below 80 %, overcharge below 99.5 %, then float; ``NOT`` unless charging."""
        if not self.charging:
            return ChargingState.NOT
        if self.charge_percent < 80.0:
            return ChargingState.BULK
        if self.charge_percent < 99.5:
            return ChargingState.OVERCHARGE
        return ChargingState.FLOAT

    @property
    def empty(self) -> bool:
        """Whether the charge has run out (below 0.01 %)."""
        return self.charge_percent < 0.01

    def step(self, dt: float, speed: float) -> None:
        """Advance ``dt`` seconds of use at ``speed`` m/s (charging if ``charging``)."""
        hours = dt / 3600.0
        drain = (100.0 / self.idle_hours + self.driving_drain * abs(speed)) * hours
        gain = 0.0
        if self.charging:
            rate = self.charge_rate if self.charge_percent < 80.0 else self.charge_rate / 3
            gain = rate * hours + drain  # the charger also powers the robot
        self.charge_percent = min(100.0, max(0.0, self.charge_percent - drain + gain))
