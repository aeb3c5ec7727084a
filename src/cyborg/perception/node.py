"""The tracker on the bus: a robot's pose and its detector's predictions in, objects out.

:class:`TrackerNode` subscribes to the robot's ``odom`` and ``pose``
(:mod:`cyborg.interfaces.robot`) and to its detector's ``predictions``
(:mod:`cyborg.interfaces.detector`), and publishes the robot's ``objects``
(:mod:`cyborg.interfaces.perception`):

* each predictions message is screened (:mod:`~cyborg.perception.screening`), placed on the
  map (:mod:`~cyborg.perception.sighting`) and tracked (:mod:`~cyborg.perception.tracker`) at
  the stamp of the image they were found in (else of the message, else the time it came) —
  the camera's clock, which is ``/clock`` under ``use_sim_time`` — and the objects are
  published at once. The robot's pose is the one at that stamp, interpolated between the
  stamped poses of ``odom`` in the map frame (:mod:`~cyborg.perception.pose_history`): a frame
  taken while the robot turned is placed as the camera saw it, however late it comes. Without
  an ``odom`` pose near the stamp (none published, another frame or another clock) it is the
  newest ``pose``, which carries no stamp;
* every :data:`REFRESH` s (wall time) the objects are forgotten and published again, so a list
  whose detector went quiet empties in time: the time then is the newest stamp plus what the
  node's clock counted since that frame came (so a detector stamping on another clock than
  the node's is followed all the same, as long as both run at one pace);
* predictions that cannot be placed are counted by reason, and so are frames that come before
  any pose; the counts go to the log as one warning per :data:`REPORT_EVERY` s of wall time
  (``dropped 12 predictions in the last 10 s: 10 no distance, 2 flood``).

All of it runs on the node's thread; nothing raises out of a callback for a bad message.
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Callable, Iterable

from cyborg.bus import Node, Qos
from cyborg.bus.msgs.cyborg_msgs.msg import Predictions
from cyborg.bus.msgs.geometry_msgs.msg import Pose2D
from cyborg.bus.msgs.nav_msgs.msg import Odometry
from cyborg.interfaces import detector, perception, robot
from cyborg.perception.objects_message import objects_message, seconds_of
from cyborg.perception.pose_history import PoseHistory
from cyborg.perception.screening import MAX_PER_FRAME, Rejections, screen
from cyborg.perception.sighting import RobotPose, locate
from cyborg.perception.tracker import Tracker, TrackerSettings

log = logging.getLogger("cyborg.perception")

REFRESH = 0.5
"""Wall-clock seconds between two publications when no predictions come."""
QUEUE = 5
"""Predictions messages the subscription holds while the node is busy (the topic keeps 1)."""
REPORT_EVERY = 10.0
"""Wall-clock seconds between two warnings about dropped predictions."""
NO_POSE = "no pose yet"
"""The reason frames that come before the robot's first pose are counted under."""


class TrackerNode:
    """Tracks what the detector of the robot under ``robot_namespace`` sees, on ``node``.

    ``now`` gives the node's clock in seconds (a :class:`~cyborg.bus.SimClock`'s ``now`` under
    ``use_sim_time``); ``labels`` names the labels tracked (none: all).
    """

    def __init__(self, node: Node, robot_namespace: str = robot.NAMESPACE,
                 detector_namespace: str | None = None, *,
                 settings: TrackerSettings | None = None, labels: Iterable[str] = (),
                 now: Callable[[], float] = time.time, limit: int = MAX_PER_FRAME) -> None:
        self.node, self.now = node, now
        self.robot_namespace = robot_namespace
        self.detector_namespace = detector_namespace or detector.detector_of_robot(
            robot_namespace)
        self.tracker = Tracker(settings)
        self.labels = tuple(labels)
        self.limit = limit
        self.pose: RobotPose | None = None
        """The newest ``pose``: the robot's pose for frames that the history does not cover."""
        self.history = PoseHistory()
        """The stamped poses of ``odom`` in the map frame, to place each frame at its stamp."""
        self.frames = 0
        """Predictions messages tracked."""
        self.dropped = Rejections()
        """Everything dropped since the node started."""
        self._unreported = Rejections()
        self._reported_at = -math.inf
        self._tracked_at = 0.0  # the node's clock when the last frame was tracked
        self._publisher = perception.OBJECTS.publisher(node, robot_namespace)
        robot.POSE.subscription(node, self._on_pose, robot_namespace)
        robot.ODOM.subscription(node, self._on_odom, robot_namespace)
        detector.PREDICTIONS.subscription(node, self._on_predictions, self.detector_namespace,
                                          qos=Qos.latched(QUEUE))
        self._timer = node.create_timer(REFRESH, self._refresh)

    def _on_pose(self, message: Pose2D) -> None:
        values = (float(message.x), float(message.y), float(message.theta))
        if all(math.isfinite(value) for value in values):
            self.pose = RobotPose(*values)

    def _on_odom(self, message: Odometry) -> None:
        if message.header.frame_id not in (robot.MAP_FRAME, ""):
            return  # an odometry frame that drifts from the map: no place for objects
        position, turn = message.pose.pose.position, message.pose.pose.orientation
        values = (float(position.x), float(position.y),
                  robot.yaw_of(float(turn.x), float(turn.y), float(turn.z), float(turn.w)))
        if all(math.isfinite(value) for value in values):
            self.history.add(seconds_of(message.header.stamp), RobotPose(*values))

    def _on_predictions(self, message: Predictions) -> None:
        detections, rejected = screen(message.predictions, labels=self.labels, limit=self.limit)
        # when the frame was taken (the image's stamp), else when it was detected, else now
        stamp = seconds_of(message.image_header.stamp) or seconds_of(message.header.stamp)
        if not (math.isfinite(stamp) and stamp > 0):
            stamp = self.now()
        pose = self.history.at(stamp) or self.pose
        if pose is None:
            if detections:
                rejected.counts[NO_POSE] += len(detections)
            self._count(rejected)
            return
        self._count(rejected)
        self.tracker.update(stamp, locate(detections, pose))
        self._tracked_at = self.now()
        self.frames += 1
        self._publish(self.tracker.newest)

    def _refresh(self) -> None:
        newest = self.tracker.newest
        if math.isfinite(newest):
            # the stamps' time now: the newest stamp plus what the node's clock counted since
            now = newest + max(0.0, self.now() - self._tracked_at)
            self.tracker.forget(now)
        else:
            now = self.now()
        self._publish(now)
        self._count(Rejections())

    def _publish(self, now: float) -> None:
        self._publisher.publish(objects_message(self.tracker.objects(), now))

    def _count(self, rejected: Rejections) -> None:
        """Adds to the counts; warns with them at most once per :data:`REPORT_EVERY` s."""
        self.dropped.add(rejected)
        self._unreported.add(rejected)
        wall = time.monotonic()
        if not self._unreported.total or wall - self._reported_at < REPORT_EVERY:
            return
        since = "" if math.isinf(self._reported_at) else \
            f" in the last {wall - self._reported_at:.0f} s"
        reasons = self._unreported.describe()
        extra = self._unreported.counts[NO_POSE]
        if extra:
            reasons = ", ".join(part for part in (reasons, f"{extra} {NO_POSE}") if part)
        log.warning("%s: dropped %d predictions%s: %s",
                    detector.PREDICTIONS.full_name(self.detector_namespace),
                    self._unreported.total, since, reasons)
        self._unreported = Rejections()
        self._reported_at = wall

    def stop(self) -> None:
        """Stops refreshing (the node is the caller's to destroy)."""
        self._timer.cancel()
