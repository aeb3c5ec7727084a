"""The robot as behaviour nodes see it: goals, pose, battery, moving and docking.

Behaviour nodes never talk to the bus themselves. They act through a :class:`Robot`, which the
tree runner puts in the blackboard's resources (``blackboard.resources["robot"]``) and which
:func:`robot_of` fetches. :class:`~cyborg.robot.bus_robot.BusRobot` is the real one (the robot's
ARNL-like interface on the bus, simulated or not); tests may pass anything with the same
methods.

:class:`MoveOutcome` and :class:`DockState` are the robot interface's own
(:mod:`cyborg.interfaces.robot`), taken from its message definitions.

Nothing here blocks a tick for long: moving returns a :class:`Move` handle that is polled,
distance queries return futures, and cancelling is sent in the background.
"""

from __future__ import annotations

import math
from concurrent.futures import Future
from dataclasses import dataclass
from typing import Protocol

from cyborg.bt import Node
from cyborg.bt.resources import fetches_resource
from cyborg.interfaces.robot import DockState as DockState
from cyborg.interfaces.robot import MoveOutcome as MoveOutcome
from cyborg.nav.geometry import Pose2D

ROBOT = "robot"
"""The key of the robot in ``Blackboard.resources``."""


@dataclass(frozen=True)
class Goal:
    """A named goal of the map (AvailableGoals): a pose, heading in radians."""

    name: str
    pose: Pose2D
    comment: str = ""
    has_heading: bool = False
    """Whether the robot turns to ``pose.theta`` on arrival (GoalWithHeading and Dock)."""


@dataclass(frozen=True)
class BatteryReading:
    """The last battery_status message."""

    charge_percent: float
    charging: bool
    dock_state: DockState
    time: float = 0.0
    """Stamp of the message, in seconds of the robot's clock."""


class Move(Protocol):
    """A move in progress, polled by the node that started it."""

    @property
    def done(self) -> bool:
        """Whether the move has ended, however it ended."""
        ...
    @property
    def outcome(self) -> MoveOutcome | None:
        """How it ended; None while it runs."""
        ...
    @property
    def message(self) -> str:
        """The robot's word on how it ended (why it failed); empty while it runs."""
        ...
    @property
    def remaining(self) -> float:
        """Metres left along the planned path, from the last feedback (inf before any)."""
        ...
    @property
    def waiting(self) -> bool:
        """Whether the robot stands waiting for people or objects to make way.

        Its path state is ``WAITING_FOR_PATH``; no progress is due meanwhile.
        """
        ...
    def cancel(self) -> None:
        """Ask the robot to stop this move (in the background); harmless when done."""
        ...


class Robot(Protocol):
    """What behaviour nodes may ask of the robot."""

    @property
    def pose(self) -> Pose2D | None:
        """The robot's last known pose; None before the first."""
        ...
    @property
    def battery(self) -> BatteryReading | None:
        """The last battery reading; None before the first."""
        ...
    def goals(self, refresh: bool = False) -> dict[str, Goal]:
        """The map's named goals (cached; ``refresh`` asks again)."""
        ...
    def move_to(self, goal: str) -> Move:
        """Start driving to the named goal (heading as the map says); raises RobotError."""
        ...
    def dock(self) -> tuple[bool, str]:
        """Ask the robot to drive to its dock and dock; ``(accepted, message)``."""
        ...
    def undock(self) -> tuple[bool, str]:
        """Ask the robot to back off its dock; ``(accepted, message)``."""
        ...
    def stop(self) -> None:
        """Abandon the current goal or docking."""
        ...
    def distance_to(self, goal: Pose2D) -> Future[float]:
        """Length of the planned path to ``goal`` (inf without a path)."""
        ...
    def closest_goal(self) -> Future[tuple[str, float]]:
        """The goal with the shortest planned path, and its length."""
        ...
    def call_for_help(self, reason: str, time: float) -> None:
        """Say on the bus that the robot needs help, why, and where it is (never blocks)."""
        ...


class RobotError(RuntimeError):
    """The robot could not do what was asked (not reachable, rejected the request)."""


@fetches_resource(ROBOT)
def robot_of(node: Node) -> Robot:
    """The robot the tree of ``node`` acts on; a clear error when the tree has none.

    A node class that calls it needs the robot as if it declared ``requires = (ROBOT,)``
    (:mod:`cyborg.bt.resources`): a tree without one is refused before its first tick.
    """
    robot: Robot | None = node.blackboard.resources.get(ROBOT)
    if robot is None:
        raise RobotError(
            f"{node.name} needs a robot to act on, and this tree has none: run it with "
            "`cyborg bt serve` or `cyborg up`, or give the tree "
            "Blackboard(resources={'robot': ...})")
    return robot


def heading_error(a: float, b: float) -> float:
    """Smallest absolute difference between two headings, in radians."""
    return abs((a - b + math.pi) % (2 * math.pi) - math.pi)
