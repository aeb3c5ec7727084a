"""A waypoint tour: the monitor drives one robot through several points, in order.

A page clicks points on the map and sends them (``{"t": "tour", "ns", "points"}``, see
:mod:`cyborg.monitor.robot_commands`); the monitor then sends one ``move_to_goal`` goal per
point (a *leg*), the next once the robot reached the last, as MobileEyes' tour of goals did.
Each step is told to every page as a ``tour`` message::

    {"t": "tour", "ns": "/cyborg", "state": "running", "leg": 2, "legs": 3,
     "points": [[x, y, θ or null], ...], "message": "leg 2 of 3: to (4.00, 1.50)"}

``state`` is ``running`` (``leg`` is the leg under way, from 1), ``done`` (every point
reached), ``failed`` (a leg did not reach its point: the tour ends there, ``message`` carries
the robot's reason and ``leg`` the leg that failed) or ``canceled`` (stopped, or replaced by
another goal; ``message`` says which).

:class:`Tour` knows nothing of the bus: it is given ``send_leg``, a coroutine that drives to
one point and returns how that ended (a :class:`~cyborg.monitor.robot_clients.GoalEnd`), and
``report``, which hears each ``tour`` message. Cancelling the tour cancels the coroutine of
the leg under way, which is expected to cancel its goal. Runs on the server's event loop.
"""

from __future__ import annotations

import asyncio
import logging
import math
from collections.abc import Awaitable, Callable, Sequence
from typing import Any

from cyborg.monitor.robot_clients import GoalEnd

log = logging.getLogger("cyborg.monitor")

Waypoint = tuple[float, float, float | None]
"""A point of a tour: x and y in metres, and the heading to arrive with (rad) or None."""
TOUR_LIMIT = 50
"""Most points a tour may have."""


def point_text(point: Waypoint) -> str:
    """A waypoint as people read it: ``(4.00, 1.50)``, with ``heading 90°`` when it has one."""
    x, y, theta = point
    heading = f" heading {round(math.degrees(theta))}°" if theta is not None else ""
    return f"({x:.2f}, {y:.2f}){heading}"


class Tour:
    """One tour of ``points`` for the robot under ``namespace``; see the module docstring."""

    def __init__(self, namespace: str, points: Sequence[Waypoint],
                 send_leg: Callable[[Waypoint], Awaitable[GoalEnd]],
                 report: Callable[[dict[str, Any]], None]) -> None:
        if not 1 <= len(points) <= TOUR_LIMIT:
            raise ValueError(f"a tour has 1 to {TOUR_LIMIT} points, not {len(points)}")
        self.namespace, self.points = namespace, list(points)
        self._send_leg, self._report = send_leg, report
        self.leg = 0
        """The leg under way (from 1); 0 before the first."""
        self.state = "running"
        self.reason = "canceled"
        self._task: asyncio.Task[None] | None = None

    @property
    def over(self) -> bool:
        """Whether the tour has ended (done, failed or canceled)."""
        return self.state != "running"

    def start(self) -> asyncio.Task[None]:
        """Runs the tour as a task on the running event loop; returns the task."""
        self._task = asyncio.get_running_loop().create_task(self.run())
        return self._task

    def cancel(self, reason: str) -> None:
        """Ends the tour with ``reason`` (told in its ``canceled`` message) and cancels the leg."""
        if self.over or self._task is None:
            return
        self.reason = reason
        self._task.cancel()

    async def run(self) -> None:
        """Drives the legs in order and tells every step; ends at the first leg that fails."""
        legs = len(self.points)
        try:
            for index, point in enumerate(self.points, start=1):
                self.leg = index
                self._tell("running", f"leg {index} of {legs}: to {point_text(point)}")
                end = await self._send_leg(point)
                if end.outcome != "reached":
                    self._tell("failed", f"leg {index} of {legs} to {point_text(point)}: "
                                         f"{end.outcome} ({end.message})")
                    return
            self._tell("done", f"all {legs} points reached")
        except asyncio.CancelledError:
            self._tell("canceled", f"{self.reason} during leg {self.leg} of {legs}")
            raise
        except Exception as exc:  # a bug, or the bus gone: the tour ends and says why
            log.exception("monitor: the tour of %s failed", self.namespace)
            self._tell("failed", f"leg {self.leg} of {legs}: {exc}")

    def _tell(self, state: str, message: str) -> None:
        self.state = state
        self._report({"t": "tour", "ns": self.namespace, "state": state, "leg": self.leg,
                      "legs": len(self.points), "points": [list(point) for point in self.points],
                      "message": message})
