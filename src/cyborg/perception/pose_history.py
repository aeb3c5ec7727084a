"""Where the robot was at a given time: a short history of stamped poses, interpolated.

A camera frame reaches the tracker some time after it was taken: the detector's work and the
bus take tens of milliseconds, and in simulation at 30x real time that is a second of simulated
time. A robot turning at 1 rad/s meanwhile would put a person two metres ahead of where they
were, placed with the newest pose. So the tracker keeps the robot's stamped poses
(``odom``, :mod:`cyborg.interfaces.robot`) of the last :attr:`PoseHistory.span` seconds and
places each frame with the pose at the frame's own stamp — the way a ROS node asks tf for a
transform at a message's stamp:

    history = PoseHistory()
    history.add(10.0, RobotPose(0.0, 0.0, 0.0))
    history.add(10.2, RobotPose(0.2, 0.0, 0.4))
    history.at(10.1)            # RobotPose(0.1, 0.0, 0.2): between the two, linearly
    history.at(10.3)            # RobotPose(0.2, 0.0, 0.4): a little newer than the newest
    history.at(3.0)             # None: long before what is kept (another clock?)

Headings are interpolated the short way round (from 3.1 to -3.1 rad passes π, not 0).
A stamp older than the newest one starts the history over: the clock went back (a simulator
restarted, a recording played again).
"""

from __future__ import annotations

import bisect
import math

from cyborg.perception.sighting import RobotPose

SPAN = 5.0
"""Seconds of poses kept: more than any detector's latency."""
AHEAD = 0.5
"""Seconds a frame's stamp may be newer than the newest pose and still take it (poses come
at 10 Hz or more; a frame stamped between two of them may arrive first)."""
BEFORE = 0.5
"""Seconds a frame's stamp may be older than the oldest pose kept and still take that one."""
MOST = 1000
"""Poses kept at most, whatever their stamps: 5 s at 200 Hz (a publisher stamping them
microseconds apart fills no more)."""


class PoseHistory:
    """The robot's stamped poses of the last ``span`` seconds (at most :data:`MOST`)."""

    def __init__(self, span: float = SPAN) -> None:
        self.span = span
        self._stamps: list[float] = []
        self._poses: list[RobotPose] = []

    def __len__(self) -> int:
        """How many poses are kept."""
        return len(self._stamps)

    def add(self, stamp: float, pose: RobotPose) -> None:
        """Keep ``pose`` (the robot at ``stamp`` s); the same stamp again replaces it."""
        if not math.isfinite(stamp):
            return
        if self._stamps and stamp < self._stamps[-1]:
            self._stamps.clear()  # the clock went back: what was kept is of another run
            self._poses.clear()
        if self._stamps and stamp == self._stamps[-1]:
            self._poses[-1] = pose
            return
        self._stamps.append(stamp)
        self._poses.append(pose)
        cut = max(bisect.bisect_left(self._stamps, stamp - self.span), len(self._stamps) - MOST)
        if cut:
            del self._stamps[:cut], self._poses[:cut]

    def at(self, stamp: float) -> RobotPose | None:
        """The robot at ``stamp``: interpolated between the poses around it; None if unknown.

        Unknown means nothing kept, or ``stamp`` more than :data:`BEFORE` s before the oldest
        pose or :data:`AHEAD` s after the newest.
        """
        stamps = self._stamps
        if not stamps or not math.isfinite(stamp):
            return None
        if stamp >= stamps[-1]:
            return self._poses[-1] if stamp - stamps[-1] <= AHEAD else None
        if stamp <= stamps[0]:
            return self._poses[0] if stamps[0] - stamp <= BEFORE else None
        after = bisect.bisect_right(stamps, stamp)
        start, end = self._poses[after - 1], self._poses[after]
        share = (stamp - stamps[after - 1]) / (stamps[after] - stamps[after - 1])
        turn = math.remainder(end.theta - start.theta, 2 * math.pi)
        return RobotPose(start.x + share * (end.x - start.x), start.y + share * (end.y - start.y),
                         math.remainder(start.theta + share * turn, 2 * math.pi))
