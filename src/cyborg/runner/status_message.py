"""The ``status`` message of one tick (``cyborg_msgs/BehaviorTreeStatus``).

What ran and how it ended, with each visited node's wall time, the active path, the halted
nodes and the mode that ticked.
"""

from __future__ import annotations

import numpy as np

from cyborg.bt.snapshot import TickSnapshot
from cyborg.bus.msgs.builtin_interfaces.msg import Time
from cyborg.bus.msgs.cyborg_msgs.msg import BehaviorTreeStatus


def status_message(snapshot: TickSnapshot, mode: str) -> BehaviorTreeStatus:
    """``snapshot`` as the runner publishes it; ``mode`` names the mode that ticked ("" none)."""
    seconds = snapshot.time
    stamp = Time(sec=int(seconds), nanosec=int((seconds % 1.0) * 1e9) % 1_000_000_000)
    visited = snapshot.visited
    return BehaviorTreeStatus(
        stamp=stamp, tick=snapshot.tick, duration=snapshot.duration,
        status=int(snapshot.status), visited_ids=[uid for uid, _ in visited],
        visited_statuses=np.array([int(status) for _, status in visited], np.uint8),
        visited_durations=np.array(snapshot.visit_durations, np.float32),
        active_ids=list(snapshot.active), halted_ids=snapshot.halted, mode=mode)
