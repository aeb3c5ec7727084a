"""Battery nodes: ``CheckBattery{threshold}`` guards a recharge branch, ``Charge{target}`` charges.

A patrol-and-recharge tree puts them together as
``Priority[CheckBattery(25) -> Recharge[MoveTo Dock, Charge 95], Patrol]``:

* :class:`CheckBattery` is a *latching guard*: while the charge is below ``threshold`` percent,
  or while its child is still RUNNING, it ticks its child and returns the child's status;
  otherwise it returns FAILURE without ticking the child. Once the robot has started to recharge
  it therefore finishes charging (the charge rises above the threshold long before the target)
  before it patrols again. With no battery reading yet, the guard stays closed.
* :class:`Charge` docks if the robot is not docked, and stays RUNNING until the charge reaches
  ``target`` percent; it fails when docking fails. It does not undock: the next move does.
  A refusal repeats every tick under the latching guard (the map has no dock): its warning is
  logged once per 10 s with a count (:mod:`cyborg.robot.rate_limited_log`).
"""

from __future__ import annotations

import logging

from typing_extensions import override

from cyborg.bt import FAILURE, RUNNING, SUCCESS, Action, Decorator, Status, register
from cyborg.robot.protocol import ROBOT, DockState, robot_of
from cyborg.robot.rate_limited_log import RateLimitedLog

log = logging.getLogger("cyborg.robot")
limited = RateLimitedLog(log)

DOCK_START_TIMEOUT = 10.0
"""Seconds (tree clock) for the robot to report DOCKING after a dock request."""


@register
class CheckBattery(Decorator):
    """Tick the child while the battery is below ``threshold`` % or the child runs."""

    requires = (ROBOT,)

    def __init__(self, threshold: float = 25.0) -> None:
        if not 0 <= threshold <= 100:
            raise ValueError(f"threshold is a percentage (0 to 100), not {threshold}")
        self.threshold = threshold

    @override
    def tick(self) -> Status:
        battery = robot_of(self).battery
        low = battery is not None and battery.charge_percent < self.threshold
        if low or self.child.status is RUNNING:
            return self.child.execute()
        return FAILURE


@register
class Charge(Action):
    """Dock if needed, then RUNNING until the battery holds ``target`` %."""

    requires = (ROBOT,)

    def __init__(self, target: float = 95.0) -> None:
        if not 0 < target <= 100:
            raise ValueError(f"target is a percentage (above 0, at most 100), not {target}")
        self.target = target
        self._requested_at: float | None = None
        self._seen_docking = False
        self.reason = ""

    @override
    def on_start(self) -> None:
        self._requested_at, self._seen_docking, self.reason = None, False, ""

    @override
    def tick(self) -> Status:
        robot = robot_of(self)
        battery = robot.battery
        if battery is None:
            return RUNNING  # no reading yet
        if battery.charge_percent >= self.target:
            return SUCCESS
        state = battery.dock_state
        if state in (DockState.DOCKING, DockState.DOCKED):
            self._seen_docking = True
            return RUNNING
        if self._requested_at is None or (state is DockState.UNDOCKED and self._seen_docking):
            if self._seen_docking:
                self.reason = "docking failed"
                return FAILURE
            accepted, message = robot.dock()
            if not accepted:
                self.reason = f"the robot cannot dock: {message}"
                limited.warning(("Charge refused", self.uid), "Charge %s: %s", self.uid,
                                self.reason)
                return FAILURE
            self._requested_at = self.now
        elif self.now < self._requested_at:  # the clock went back: count again from now
            self._requested_at = self.now
        elif self.now - self._requested_at > DOCK_START_TIMEOUT:
            self.reason = f"the robot did not start docking within {DOCK_START_TIMEOUT:g} s"
            limited.warning(("Charge timeout", self.uid), "Charge %s: %s", self.uid,
                            self.reason)
            return FAILURE
        return RUNNING

    def on_halt(self) -> None:
        """Stops the robot if it is still driving to the dock that this node asked for."""
        battery = robot_of(self).battery
        if self._requested_at is not None and battery is not None and \
                battery.dock_state is DockState.DOCKING:
            robot_of(self).stop()  # abandon the drive to the dock
