"""Docking and undocking at the map's Dock, in ARNL's states.

``UNDOCKED`` → (dock) → ``DOCKING``: drive to the Dock pose with its heading, then creep
forward ``depth`` metres onto the charger (stopping early if the bumper touches), then wait
``power_delay`` seconds for the charger's power → ``DOCKED`` (charging). ``DOCKED`` → (undock)
→ ``UNDOCKING``: charging off, wait ``undock_wait`` seconds, back out → ``UNDOCKED``. A failed
drive to the dock returns to ``UNDOCKED`` with the reason in ``message``. The states are those
``battery_status`` reports (:class:`cyborg.interfaces.robot.DockState`).
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum

from cyborg.interfaces.robot import DockState as DockState


class DockPhase(StrEnum):
    """Steps inside DOCKING and UNDOCKING."""

    NONE = "none"
    APPROACH = "approach"  # driving to the Dock pose
    DRIVE_IN = "drive_in"  # creeping onto the charger
    POWER = "power"  # waiting for the charger's power
    WAIT = "wait"  # undocking: charging off, waiting
    BACK_OUT = "back_out"


@dataclass(frozen=True)
class DockSettings:
    """Distances (m), speeds (m/s) and waits (s) of docking and undocking."""

    depth: float = 0.3  # metres driven forward from the Dock pose onto the charger
    creep_speed: float = 0.1  # m/s in and out
    power_delay: float = 2.0  # seconds until the charger delivers power
    undock_wait: float = 5.0  # seconds between switching charging off and backing out
    back_out: float = 0.6  # metres backed out from the charger


@dataclass
class Docking:
    """Where the docking sequence stands; the simulator drives it."""

    settings: DockSettings = DockSettings()
    state: DockState = DockState.UNDOCKED
    phase: DockPhase = DockPhase.NONE
    phase_started: float = 0.0
    travelled_from: tuple[float, float] = (0.0, 0.0)
    message: str = ""
    docks: int = 0  # completed dockings

    def enter(self, state: DockState, phase: DockPhase, now: float,
              position: tuple[float, float] = (0.0, 0.0)) -> None:
        """Move to ``state`` and ``phase`` at simulated time ``now`` (s).

        ``position`` (x, y in metres) is where the distance driven in the phase is measured from.
        """
        self.state, self.phase, self.phase_started = state, phase, now
        self.travelled_from = position
