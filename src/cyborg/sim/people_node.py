"""The simulated people's true poses on the bus: ``sim/people`` of the simulation contract.

A ``geometry_msgs/PoseArray`` (:data:`cyborg.interfaces.simulation.PEOPLE`) in the ``map``
frame, stamped with simulated time, one pose per person in the crowd's fixed order, each facing
where that person walks. It is published after sensor steps, at most ``max_publish_rate`` times
per wall-clock second (as the robot's pose); the topic is latched, so a late subscriber gets
the last one at once.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable

from cyborg.bus import Node
from cyborg.bus.msgs.builtin_interfaces.msg import Time
from cyborg.bus.msgs.geometry_msgs.msg import PoseArray
from cyborg.bus.msgs.std_msgs.msg import Header
from cyborg.interfaces.robot import MAP_FRAME
from cyborg.interfaces.simulation import PEOPLE
from cyborg.sim.loop import RobotLoop
from cyborg.sim.people import Crowd
from cyborg.sim.simulator import Simulator


class PeoplePublisher:
    """Publishes ``crowd``'s poses on ``node`` after ``loop``'s sensor steps; see the module doc.

    ``clock`` gives wall-clock seconds for the publishing limit.
    """

    def __init__(self, node: Node, loop: RobotLoop, crowd: Crowd, max_publish_rate: float = 30.0,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self.node, self.crowd, self.clock = node, crowd, clock
        self._min_period = 1.0 / max_publish_rate
        self._published_at = -math.inf
        self.publisher = PEOPLE.publisher(node)
        loop.on_sensor.append(self._publish)

    def message(self, seconds: float) -> PoseArray:
        """The crowd's poses now, stamped ``seconds`` of simulated time."""
        nanoseconds = round(seconds * 1e9)
        header = Header(stamp=Time(sec=nanoseconds // 1_000_000_000,
                                   nanosec=nanoseconds % 1_000_000_000), frame_id=MAP_FRAME)
        return PoseArray(header=header, poses=[person.pose.to_pose().to_message()
                                               for person in self.crowd.people])

    def _publish(self, sim: Simulator) -> None:
        now = self.clock()
        if self.node.destroyed or now - self._published_at < self._min_period:
            return
        self._published_at = now
        try:
            self.publisher.publish(self.message(sim.time))
        except RuntimeError:
            if not self.node.destroyed:  # the node went while publishing: nothing to say
                raise
