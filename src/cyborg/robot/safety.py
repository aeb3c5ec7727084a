"""When the robot cannot go on by itself: ``StopSafely`` stops it, ``CallForHelp`` says so.

The bundled mission's critical mode (docs/modes.md) is the tree
``MemSequence[StopSafely, CallForHelp]``:

* :class:`StopSafely` abandons whatever the robot is doing — a goal, a drive to the dock —
  by asking the robot to stop, and succeeds once the robot has answered. Leaving the mode
  before halts the old tree, so a running ``MoveTo`` has cancelled its own goal already; the
  stop covers what no node of the new tree owns. When the robot does not answer it is
  asked again at the next tick (a warning once per 10 s), RUNNING meanwhile.
* :class:`CallForHelp` calls for help on the robot's ``help`` topic
  (:mod:`cyborg.interfaces.help`: the robot, the pose, the charge and ``reason``) when it
  starts and again every ``every`` seconds of the tree's clock, and stays RUNNING: the
  robot waits where it stopped, asking, until something outside the tree (someone
  arriving, a mode change) ends the wait. With ``near`` naming a blackboard key (the
  bundled mission's ``closest_goal``, kept fresh by a ``ClosestGoal`` service on the tree's
  root), the reason ends with where the robot is: ``"…; near Library"``.
"""

from __future__ import annotations

import logging
import math

from typing_extensions import override

from cyborg.bt import RUNNING, SUCCESS, Action, Status, register
from cyborg.robot.protocol import ROBOT, RobotError, robot_of
from cyborg.robot.rate_limited_log import RateLimitedLog

log = logging.getLogger("cyborg.robot")
limited = RateLimitedLog(log)


@register
class StopSafely(Action):
    """Ask the robot to stop; SUCCESS once it has answered."""

    requires = (ROBOT,)

    @override
    def tick(self) -> Status:
        try:
            robot_of(self).stop()
        except RobotError as exc:
            limited.warning(("StopSafely", self.uid), "StopSafely %s: the robot did not stop, "
                            "asking again: %s", self.uid, exc)
            return RUNNING
        return SUCCESS


@register
class CallForHelp(Action):
    """Call for help now and every ``every`` seconds; RUNNING for as long as it runs.

    ``near``: a blackboard key holding the name of the goal the robot is nearest to (written
    by a ``ClosestGoal`` service); when set and known, the reason says ``"; near <goal>"``.
    """

    requires = (ROBOT,)

    def __init__(self, reason: str = "the robot needs help", every: float = 60.0,
                 near: str = "") -> None:
        if not reason.strip():
            raise ValueError("reason is empty: say why the robot calls for help")
        if not math.isfinite(every) or every <= 0:
            raise ValueError(f"every must be a positive number of seconds, not {every}")
        self.reason, self.every, self.near = reason, every, near
        self.calls = 0
        """How many calls this node has made, over all its activations."""
        self._last: float | None = None

    @override
    def on_start(self) -> None:
        self._last = None

    @override
    def tick(self) -> Status:
        now = self.now
        if self._last is None or now - self._last >= self.every or now < self._last:
            robot_of(self).call_for_help(self._reason(), now)
            self._last = now
            self.calls += 1
        return RUNNING

    def _reason(self) -> str:
        """The reason, with the goal the robot is nearest to when ``near`` names one."""
        place = self.blackboard.get(self.near) if self.near else None
        return f"{self.reason}; near {place}" if isinstance(place, str) and place else self.reason
