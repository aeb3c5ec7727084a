"""``Dock`` and ``Undock``: ask the robot to dock or undock and wait until it has.

Both are RUNNING until the robot reports the wanted dock state, succeed at once when it is
already there, and fail when the robot refuses (no dock on the map, not docked) or when the
state does not come within ``timeout`` seconds of the tree's clock. A halted Dock stops the
drive to the dock.
"""

from __future__ import annotations

from typing_extensions import override

from cyborg.bt import FAILURE, RUNNING, SUCCESS, Action, Status, register
from cyborg.robot.protocol import ROBOT, DockState, robot_of


class _DockAction(Action):
    requires = (ROBOT,)
    wanted: DockState
    on_the_way: DockState

    def __init__(self, timeout: float = 300.0) -> None:
        if timeout <= 0:
            raise ValueError(f"timeout must be positive, not {timeout}")
        self.timeout = timeout
        self.reason = ""
        self._started = 0.0
        self._asked = False

    def request(self) -> tuple[bool, str]:
        """Asks the robot for the change: ``(accepted, message)``."""
        raise NotImplementedError

    def on_start(self) -> None:
        self._started, self._asked, self.reason = self.now, False, ""

    def tick(self) -> Status:
        battery = robot_of(self).battery
        state = battery.dock_state if battery is not None else DockState.UNKNOWN
        if state is self.wanted:
            return SUCCESS
        if not self._asked and state is not self.on_the_way:
            accepted, message = self.request()
            if not accepted:
                self.reason = message
                return FAILURE
            self._asked = True
        if self.now < self._started:  # the clock went back: count again from now
            self._started = self.now
        if self.now - self._started > self.timeout:
            self.reason = f"not {self.wanted.value} after {self.timeout:g} s"
            return FAILURE
        return RUNNING


@register
class Dock(_DockAction):
    """Drive to the map's dock and dock."""

    wanted, on_the_way = DockState.DOCKED, DockState.DOCKING

    @override
    def request(self) -> tuple[bool, str]:
        return robot_of(self).dock()

    def on_halt(self) -> None:
        """Stops the robot if it is still driving to the dock that this node asked for."""
        battery = robot_of(self).battery
        if self._asked and battery is not None and battery.dock_state is DockState.DOCKING:
            robot_of(self).stop()


@register
class Undock(_DockAction):
    """Leave the dock."""

    wanted, on_the_way = DockState.UNDOCKED, DockState.UNDOCKING

    @override
    def request(self) -> tuple[bool, str]:
        return robot_of(self).undock()
