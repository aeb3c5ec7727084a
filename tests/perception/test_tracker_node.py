"""The tracker on the bus: pose and predictions in, the robot's objects out; bad input counted
in the log, never raised."""

from __future__ import annotations

import logging
import math
from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest

from cyborg.bus import BusConfig, Context, Node
from cyborg.bus.component import LaunchError, NodeSpec
from cyborg.bus.msgs.builtin_interfaces.msg import Time
from cyborg.bus.msgs.geometry_msgs.msg import (
    Point,
    Pose,
    Pose2D,
    PoseWithCovariance,
    Quaternion,
    Twist,
    TwistWithCovariance,
    Vector3,
)
from cyborg.bus.msgs.nav_msgs.msg import Odometry
from cyborg.bus.msgs.std_msgs.msg import Header
from cyborg.bus.wire import EntityKind
from cyborg.interfaces import detector, perception, robot
from cyborg.perception import component
from cyborg.perception.component import RunningTracker
from cyborg.perception.screening import FLOOD, MAX_PER_FRAME, NO_DISTANCE
from tests.bus.bus_peer import wait_for
from tests.perception.predictions import prediction, predictions

ROBOT = "/cyborg"


@pytest.fixture
def bus() -> Iterator[Context]:
    with Context(BusConfig.isolated()) as context:
        yield context


@pytest.fixture
def tracker(bus: Context) -> Iterator[RunningTracker]:
    running = component.start(bus, NodeSpec("tracker", component.TRACKER_NAME, ROBOT,
                                            where="test: tracker"))
    yield running
    running.stop()


class Peer:
    """The robot and its detector as the tracker sees them, and a reader of its objects."""

    def __init__(self, bus: Context) -> None:
        self.node = Node("peer", ROBOT, context=bus)
        self.pose = robot.POSE.publisher(self.node)
        self.predictions = detector.PREDICTIONS.publisher(self.node,
                                                          detector.detector_of_robot(ROBOT))
        self.objects: list[Any] = []
        perception.OBJECTS.subscription(self.node, self.objects.append)

    def wait_until_heard(self, tracker: RunningTracker) -> None:
        """Until the tracker hears the pose and the predictions, and this hears its objects."""
        assert wait_for(lambda: self.node.context.graph.count(
            detector.PREDICTIONS.full_name(tracker.tracker.detector_namespace),
            EntityKind.SUBSCRIPTION) and self.objects, 20), \
            "the tracker never published its objects"
        for _ in range(100):
            self.pose.publish(Pose2D(x=1.0, y=1.0, theta=0.0))
            if wait_for(lambda: tracker.tracker.pose is not None, 0.5):
                break
        assert tracker.tracker.pose is not None, "the tracker never heard the pose"


def test_a_person_straight_ahead_is_published_on_the_map(bus: Context,
                                                           tracker: RunningTracker) -> None:
    peer = Peer(bus)
    peer.wait_until_heard(tracker)
    for step in range(3):
        peer.predictions.publish(predictions([prediction("person", 2.0)], 10.0 + step * 0.1))
    assert wait_for(lambda: tracker.tracker.frames == 3, 20)
    assert wait_for(lambda: peer.objects and peer.objects[-1].objects
                    and peer.objects[-1].objects[0].times_seen == 3, 20)
    message = peer.objects[-1]
    (person,) = message.objects
    assert message.header.frame_id == "map"
    assert person.label == "person" and person.id == 1
    mount = perception.CAMERA_MOUNT.x
    assert (person.position.x, person.position.y) == pytest.approx((1.0 + mount + 2.0, 1.0))
    assert person.distance == pytest.approx(mount + 2.0) and person.bearing == pytest.approx(0)
    assert person.last_seen.sec == 10 and 0 < person.confidence <= 1


def odometry(stamp: float, x: float, y: float, theta: float, frame: str = "map") -> Odometry:
    """The robot at ``(x, y, theta)`` at ``stamp`` s, as the simulator's ``odom`` says it."""
    whole = math.floor(stamp)
    header = Header(stamp=Time(sec=whole, nanosec=round((stamp - whole) * 1e9)), frame_id=frame)
    orientation = Quaternion(x=0.0, y=0.0, z=math.sin(theta / 2), w=math.cos(theta / 2))
    pose = Pose(position=Point(x=x, y=y, z=0.0), orientation=orientation)
    return Odometry(header=header, child_frame_id="base_link",
                    pose=PoseWithCovariance(pose=pose, covariance=np.zeros(36)),
                    twist=TwistWithCovariance(twist=Twist(
                        linear=Vector3(x=0.0, y=0.0, z=0.0),
                        angular=Vector3(x=0.0, y=0.0, z=0.0)), covariance=np.zeros(36)))


def test_a_frame_is_placed_with_the_pose_at_its_stamp_not_the_newest(
        bus: Context, tracker: RunningTracker) -> None:
    """The robot turns from facing +x (stamp 20.0) to facing +y (stamp 20.2); a person 2 m
    straight ahead in a frame stamped 20.0 that arrives after both poses is on the +x side,
    one stamped 20.1 halfway (45 degrees). Odometry in another frame than the map is not
    used; a frame stamped far from every odometry pose takes the newest ``pose``."""
    peer = Peer(bus)
    peer.wait_until_heard(tracker)  # the newest pose: (1, 1) facing +x
    odom = robot.ODOM.publisher(peer.node)
    assert wait_for(lambda: peer.node.context.graph.count(
        robot.ODOM.full_name(ROBOT), EntityKind.SUBSCRIPTION), 20)
    odom.publish(odometry(20.0, 0.0, 0.0, 0.0))
    odom.publish(odometry(20.2, 0.0, 0.0, math.pi / 2))
    odom.publish(odometry(20.2, 50.0, 50.0, 0.0, frame="odom"))  # drifting frame: left out
    assert wait_for(lambda: len(tracker.tracker.history) == 2, 20)
    reach = perception.CAMERA_MOUNT.x + 2.0
    for label, stamp, where in (("person", 20.0, (reach, 0.0)),
                                ("dog", 20.1, (reach / math.sqrt(2),) * 2),
                                ("chair", 40.0, (1.0 + reach, 1.0))):
        wanted = tracker.tracker.frames + 1  # each its own label: a new object where seen
        peer.predictions.publish(predictions([prediction(label, 2.0)], stamp))
        assert wait_for(lambda: tracker.tracker.frames == wanted, 20)  # noqa: B023
        placed = [(item.x, item.y) for item in tracker.tracker.tracker.objects()
                  if item.label == label]
        assert placed == [pytest.approx(where, abs=1e-6)], (label, placed)


def test_a_flood_and_bad_distances_are_counted_in_one_warning_without_a_traceback(
        bus: Context, tracker: RunningTracker, caplog: pytest.LogCaptureFixture) -> None:
    peer = Peer(bus)
    peer.wait_until_heard(tracker)
    caplog.set_level(logging.WARNING, "cyborg")
    flood = [prediction("person", 1.0 + (i % 50) / 10, bearing=(i % 90 - 45) / 100)
             for i in range(10_000)]
    flood += [prediction(distance=math.nan), prediction(distance=-2.0)]
    peer.predictions.publish(predictions(flood, 20.0))
    assert wait_for(lambda: tracker.tracker.frames == 1, 30), "the flood stalled the tracker"
    counts = tracker.tracker.dropped.counts
    assert counts[FLOOD] == 10_000 - MAX_PER_FRAME and counts[NO_DISTANCE] == 2
    assert len(tracker.tracker.tracker) <= MAX_PER_FRAME
    warnings = [record.getMessage() for record in caplog.records
                if record.name == "cyborg.perception"]
    assert len(warnings) == 1 and "9800 flood" in warnings[0] and "2 no distance" in warnings[0]
    assert "/cyborg/detector/predictions" in warnings[0]
    assert not [record for record in caplog.records if record.levelno >= logging.ERROR]
    peer.predictions.publish(predictions([prediction(distance=math.nan)], 20.1))
    assert wait_for(lambda: tracker.tracker.frames == 2, 20)
    assert len([record for record in caplog.records
                if record.name == "cyborg.perception"]) == 1, "the next is rate-limited"


def test_predictions_before_any_pose_are_counted_not_placed(bus: Context,
                                                            tracker: RunningTracker) -> None:
    peer = Peer(bus)
    assert wait_for(lambda: peer.objects, 20)
    peer.predictions.publish(predictions([prediction()], 1.0))
    assert wait_for(lambda: tracker.tracker.dropped.counts["no pose yet"] == 1, 20)
    assert len(tracker.tracker.tracker) == 0


def test_a_tracker_with_a_bad_gate_is_refused_naming_the_entry(bus: Context) -> None:
    with pytest.raises(LaunchError, match=r"up.json: node 4: .*gate"):
        component.start(bus, NodeSpec("tracker", "tracker", ROBOT, {"gate": -1.0},
                                      where="up.json: node 4"))


def test_the_labels_tracked_are_a_string_array_and_text_is_refused(bus: Context) -> None:
    running = component.start(bus, NodeSpec("tracker", "tracker", ROBOT,
                                            {"labels": ["person", "dog"]}))
    try:
        assert running.tracker.labels == ("person", "dog")
    finally:
        running.stop()
    every = component.start(bus, NodeSpec("tracker", "t2", ROBOT))
    assert every.tracker.labels == ()
    every.stop()
    with pytest.raises(ValueError, match=r"labels.*string array"):
        component.start(bus, NodeSpec("tracker", "t3", ROBOT, {"labels": "person"}))
