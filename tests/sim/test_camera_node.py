"""The simulated camera and people on the bus: the detector's messages with the same fields
filled as the detector node fills them, under the robot's detector namespace; the people's
true poses; parameters that cannot be are refused naming the entry."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import pytest

from cyborg.bus import BusConfig, Context, Node
from cyborg.bus.component import LaunchError, NodeSpec
from cyborg.bus.msgs.cyborg_msgs.msg import Predictions
from cyborg.bus.msgs.geometry_msgs.msg import PoseArray
from cyborg.bus.msgs.sensor_msgs.msg import Image
from cyborg.bus.msgs.vision_msgs.msg import Detection2DArray
from cyborg.interfaces import detection_messages, detector, simulation
from cyborg.sim import component
from cyborg.sim.camera import CameraSpec
from cyborg.sim.people_and_camera import CAMERA_NAME
from cyborg.vision import detector_node
from tests.running_system import wait_until
from tests.small_maps import room_map, write

# the robot at home facing a person who stands 3 m ahead, and a chair beside them
CAIRNS = ['RobotHome 1000 1500 0 "" ICON "home"', 'Goal 4000 1500 0 "" ICON "spot"',
          'Sim.Person 4000 1500 0 "spot" ICON "ann"',
          'Sim.Object 4000 2500 0 "chair 0.9 0.3" ICON "c1"']


def test_the_detectors_messages_are_built_by_the_same_functions() -> None:
    used = vars(detector_node)
    assert used["predictions_message"] is detection_messages.predictions_message
    assert used["detection_array_message"] is detection_messages.detection_array_message


def test_the_camera_publishes_what_the_detector_would_and_people_are_on_sim_people(
        tmp_path: Path) -> None:
    path = write(tmp_path, "room.map", room_map(CAIRNS))
    with Context(BusConfig.isolated()) as context:
        running = component.start(context, NodeSpec(
            "simulator", "arnl", "/lab", {"map": str(path), "camera": True, "speed": 5,
                                          "camera_image": True}))
        listener = Node("listener", "/test", context=context)
        got: dict[str, list[Any]] = {"predictions": [], "detections": [], "image": [],
                                     "people": []}
        where = detector.detector_of_robot("/lab")
        detector.PREDICTIONS.subscription(listener, got["predictions"].append, namespace=where)
        detector.DETECTIONS.subscription(listener, got["detections"].append, namespace=where)
        detector.DETECTION_IMAGE.subscription(listener, got["image"].append, namespace=where)
        simulation.PEOPLE.subscription(listener, got["people"].append, namespace="/lab")
        try:
            assert "1 people walking" in running.describe() and where in running.describe()
            wait_until(lambda: any(len(m.predictions) == 2 for m in got["predictions"])
                       and got["image"] and got["people"], 60, "both seen, drawn, people")
            predictions: Predictions = next(m for m in got["predictions"]
                                            if len(m.predictions) == 2)
            stamp = predictions.image_header.stamp
            wait_until(lambda: any(m.header.stamp == stamp for m in got["detections"]), 10,
                       "the same frame's detections")
            detections: Detection2DArray = next(m for m in got["detections"]
                                                if m.header.stamp == stamp)
        finally:
            running.stop()
            listener.destroy()
    assert running.cameras[0].fq_name == f"{where}/{CAMERA_NAME}"
    assert predictions.header.frame_id == predictions.image_header.frame_id == "camera_left"
    assert predictions.header.stamp == stamp, "stamped with the frame's simulated time"
    assert {p.label for p in predictions.predictions} == {"person", "chair"}
    for prediction, found in zip(predictions.predictions, detections.detections, strict=True):
        corners = [(c.x, c.y) for c in prediction.bounding_box.points]
        (x1, y1), (x2, _), (_, y2), (x0, _) = corners
        assert x0 == x1 < x2 and y1 < y2, "top-left, top-right, bottom-right, bottom-left"
        assert 0.5 <= prediction.confidence <= 1.0 and 2.0 < prediction.distance < 4.0
        assert found.header == detections.header and found.header.stamp == stamp
        hypothesis = found.results[0]
        assert hypothesis.hypothesis.class_id == prediction.label
        assert hypothesis.hypothesis.score == prediction.confidence
        assert hypothesis.pose.pose.position.z == prediction.distance
        assert found.bbox.center.position.x == pytest.approx((x1 + x2) / 2)
        assert found.bbox.size_y == pytest.approx(y2 - y1)
    person = next(p for p in predictions.predictions if p.label == "person")
    assert person.distance == pytest.approx(3.0 - CameraSpec().mount_x, abs=0.2)
    image: Image = got["image"][-1]
    assert (image.encoding, image.width, image.height) == ("bgr8", 672, 376)
    people: PoseArray = got["people"][-1]
    assert people.header.frame_id == "map" and len(people.poses) == 1
    assert math.hypot(people.poses[0].position.x - 4.0, people.poses[0].position.y - 1.5) < 0.5


@pytest.mark.parametrize("people", [-1, 2.5, True, "3"])
def test_a_count_of_people_that_cannot_be_is_refused_naming_the_entry(
        tmp_path: Path, people: object) -> None:
    path = write(tmp_path, "room.map", room_map(CAIRNS))
    with Context(BusConfig.isolated()) as context:
        spec = NodeSpec("simulator", "arnl", "/", {"map": str(path), "people": people},
                        where="up.toml: node 1 (arnl)")
        with pytest.raises(LaunchError, match=r"^up.toml: node 1 \(arnl\): parameter `people` "
                                              r"must be a whole number, 0 or more"):
            component.start(context, spec)


def test_a_bad_person_on_the_map_is_refused_naming_the_line(tmp_path: Path) -> None:
    path = write(tmp_path, "room.map", room_map([*CAIRNS, 'Sim.Person 3000 1000 0 "nowhere" '
                                                            'ICON "bo"']))
    said = r"room\.map:7: Sim\.Person 'bo': waypoint 'nowhere' is neither a goal"
    with Context(BusConfig.isolated()) as context, pytest.raises(LaunchError, match=said):
        component.start(context, NodeSpec("simulator", "arnl", "/", {"map": str(path)}))
