"""End to end in simulated time: a camera's predictions, the tracker, and a tree that turns the
simulated robot to face a person and greets them.

A stand-in camera publishes, for each of the simulator's poses, what the ZED would see of a
person standing at a fixed point of the map (the contract's camera model and mount), stamped on
``/clock``, on the detector's topic; the tracker places it on the map; the tree
``Sequence[ObjectDetected, FaceObject, ClosestObject, Say]`` runs on the robot through the bus.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import pytest

from cyborg.bus import Node, SimClock
from cyborg.bus.component import NodeSpec
from cyborg.bus.msgs.geometry_msgs.msg import Pose2D
from cyborg.interfaces import detector, perception, robot
from cyborg.interfaces.perception import CAMERA, CAMERA_MOUNT
from cyborg.perception import component as tracker_component
from tests.perception.predictions import prediction, predictions
from tests.running_system import running_system, wait_until, write_tree
from tests.small_maps import room_map, write

PERSON = (4.0, 4.5)
START = 'Goal 2000 3000 0 "" ICON "start"'


class StandInCamera:
    """Sees the person at :data:`PERSON` from each pose the robot publishes, as the ZED would."""

    def __init__(self, node: Node) -> None:
        self.clock = SimClock(node)
        self.sent = 0
        self._publisher = detector.PREDICTIONS.publisher(node, detector.detector_of_robot(
            robot.NAMESPACE))
        robot.POSE.subscription(node, self._on_pose, robot.NAMESPACE)

    def _on_pose(self, pose: Pose2D) -> None:
        cos, sin = math.cos(pose.theta), math.sin(pose.theta)
        camera_x, camera_y = pose.x + CAMERA_MOUNT.x * cos, pose.y + CAMERA_MOUNT.x * sin
        dx, dy = PERSON[0] - camera_x, PERSON[1] - camera_y
        bearing = math.remainder(math.atan2(dy, dx) - pose.theta, 2 * math.pi)
        seen = []
        if abs(bearing) < CAMERA.horizontal_fov / 2:
            depth = math.hypot(dx, dy) * math.cos(bearing)
            seen = [prediction("person", depth, bearing, confidence=0.85)]
        self._publisher.publish(predictions(seen, self.clock.now()))
        self.sent += 1


@pytest.mark.heavy
def test_the_tree_turns_the_robot_to_face_a_person_and_greets_them(tmp_path: Path) -> None:
    map_path = write(tmp_path, "room.map", room_map([START]))
    tree = write_tree(tmp_path, {"name": "Sequence", "composite": True, "children": [
        {"name": "ObjectDetected", "props": {"label": "person", "maxDistance": 4}},
        {"name": "FaceObject", "props": {"label": "person", "tolerance": 0.1}},
        {"name": "ClosestObject", "props": {"label": "person"}},
        {"name": "Say", "props": {"text": "Hello {closest.label}!"}}]})
    with running_system(map_path, tree, speed=5.0, start="start") as system:
        tracker = tracker_component.start(system.context, NodeSpec(
            "tracker", "tracker", robot.NAMESPACE, {"use_sim_time": True}))
        try:
            camera = StandInCamera(Node("camera", "/test", context=system.context))
            said: list[Any] = []
            perception.SAY.subscription(system.client, said.append, robot.NAMESPACE)
            start_heading = system.sim.pose.theta
            wait_until(lambda: said, 90, "the greeting")
            assert said[0].data == "Hello person!"
            assert camera.sent > 0 and tracker.tracker.frames > 0
            pose = system.sim.pose
            facing = math.atan2(PERSON[1] - pose.y, PERSON[0] - pose.x)
            assert abs(start_heading - facing) > 0.5, "the person was off to the side at first"
            assert abs(math.remainder(pose.theta - facing, 2 * math.pi)) < 0.2, \
                "the robot faces the person when it greets"
            assert math.hypot(pose.x - 2.0, pose.y - 3.0) < 0.1, "it turned on the spot"
        finally:
            tracker.stop()
