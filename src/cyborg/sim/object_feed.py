"""The tracker's objects fed to the simulated robot's navigator as temporary obstacles.

The simulator's node subscribes to its robot's ``objects``
(:data:`cyborg.interfaces.perception.OBJECTS`, the tracker's list in the ``map`` frame) and
hands each object of an obstacle label to the navigator's
:class:`~cyborg.nav.temporary_obstacles.TemporaryObstacles`, keyed by the tracker's id, so the
robot plans around people it has seen, or waits for them (:mod:`cyborg.sim.navigator`). Two
parameters of the simulator's node (see :mod:`cyborg.sim.component`) govern it:

===================  ===================================================================
parameter            meaning (default)
===================  ===================================================================
``avoid_objects``    whether to subscribe at all (true)
``obstacle_labels``  the labels that are obstacles (:data:`OBSTACLE_LABELS`: ``person``);
                     an empty string alone means every label
===================  ===================================================================

**Time.** An object's age is read on the tracker's own clock (the list's stamp minus the
object's ``last_seen``) and set back from the simulator's time when the list arrives, so a
tracker on the wall clock and a simulation running 30 times faster still agree on what was
seen when. A list in another frame than ``map`` is ignored, and so is an object whose position
is not a finite number; both are counted (:attr:`ObjectFeed.ignored`) and logged once.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Iterable

from cyborg.bus import Node
from cyborg.bus.component import NodeSpec
from cyborg.bus.msgs.cyborg_msgs.msg import TrackedObjects
from cyborg.interfaces import perception
from cyborg.sim.loop import RobotLoop

log = logging.getLogger("cyborg.sim")

OBSTACLE_LABELS: tuple[str, ...] = ("person",)
"""Labels whose objects the simulated robot plans around unless told otherwise: people. Other
things the detector names (a chair, a bottle on a table) are furniture the laser sees, or not
in the robot's way at all."""


def _seconds(stamp: object) -> float:
    return float(stamp.sec) + float(stamp.nanosec) * 1e-9  # type: ignore[attr-defined]


class ObjectFeed:
    """Subscribes ``node`` to its robot's ``objects`` and feeds ``loop``'s navigator.

    ``labels``: the obstacle labels (empty: every label). Callbacks run on the node's thread and
    hold the loop's lock while they touch the simulator.
    """

    def __init__(self, node: Node, loop: RobotLoop,
                 labels: Iterable[str] = OBSTACLE_LABELS) -> None:
        self.loop = loop
        self.labels = frozenset(labels)
        self.taken = 0
        """Objects handed to the navigator so far."""
        self.ignored = 0
        """Objects left out: a list in another frame, a position that is not a number."""
        self._warned = False
        self.subscription = perception.OBJECTS.subscription(node, self._on_objects)

    def _on_objects(self, message: TrackedObjects) -> None:
        frame = str(message.header.frame_id)
        if frame not in (perception.MAP_FRAME, ""):
            self._ignore(len(message.objects), f"a list in frame {frame!r}, not "
                                                f"{perception.MAP_FRAME!r}")
            return
        listed = _seconds(message.header.stamp)
        with self.loop.lock:
            simulator = self.loop.simulator
            now, obstacles = simulator.time, simulator.navigator.obstacles
            for item in message.objects:
                if self.labels and str(item.label) not in self.labels:
                    continue
                x, y = float(item.position.x), float(item.position.y)
                if not (math.isfinite(x) and math.isfinite(y)):
                    self._ignore(1, f"object {int(item.id)} at a position that is not a number")
                    continue
                age = listed - _seconds(item.last_seen)
                seen_at = now - (age if math.isfinite(age) and age > 0 else 0.0)
                if obstacles.see(int(item.id), x, y, seen_at,
                                 (float(item.velocity.x), float(item.velocity.y))):
                    self.taken += 1  # (a sighting older than the one held changes nothing)

    def _ignore(self, count: int, why: str) -> None:
        self.ignored += count
        if not self._warned:
            self._warned = True
            log.warning("objects: ignoring %s (said once; counted in ObjectFeed.ignored)", why)


def follow_objects(node: Node, loop: RobotLoop, spec: NodeSpec) -> ObjectFeed | None:
    """Declare ``avoid_objects`` and ``obstacle_labels`` on ``node`` and feed ``loop``.

    None when ``avoid_objects`` is false; a parameter of the wrong type refuses ``spec``.
    """
    params = node.parameters
    try:
        avoid = params.declare("avoid_objects", True, "plan around the tracker's objects",
                               read_only=True)
        labels = params.declare("obstacle_labels", list(OBSTACLE_LABELS),
                                "labels that are obstacles (empty string: every label)",
                                read_only=True)
    except (TypeError, ValueError) as exc:
        raise spec.error(str(exc)) from exc
    if not avoid:
        return None
    return ObjectFeed(node, loop, [str(label) for label in labels if label])
