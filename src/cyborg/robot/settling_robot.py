"""The robot of a tree runner on the bus, which a stopping runner can wait for.

Halting a MoveTo only *sends* the cancel (the tick must not block), so a runner that destroyed
its bus nodes right after halting would withdraw the cancel's client before the robot
answered, and the robot would drive on. :class:`SettlingBusRobot` remembers the moves it
started, and :meth:`~SettlingBusRobot.settle` waits until every one has ended: stopping a tree
runner (:mod:`cyborg.runner.component`) calls it between the halt and the nodes' end.
"""

from __future__ import annotations

import time

from cyborg.bus import Node
from cyborg.interfaces import robot
from cyborg.robot.bus_robot import BusMove, BusRobot


class SettlingBusRobot(BusRobot):
    """The robot under ``namespace`` on the bus, remembering the moves it started."""

    def __init__(self, node: Node, namespace: str = robot.NAMESPACE) -> None:
        super().__init__(node, namespace)
        self._moves: list[BusMove] = []

    def move_to(self, goal: str) -> BusMove:
        """Starts a move to ``goal`` (see :meth:`BusRobot.move_to`) and remembers it."""
        move = super().move_to(goal)
        self._moves = [*(earlier for earlier in self._moves if not earlier.done), move]
        return move

    def settle(self, timeout: float = 5.0) -> bool:
        """Waits (wall time, at most ``timeout``) until every move has ended; True if all did."""
        deadline = time.monotonic() + timeout
        while any(not move.done for move in self._moves):
            if time.monotonic() > deadline:
                return False
            time.sleep(0.01)
        return True
