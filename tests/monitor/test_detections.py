"""What the robot's detector saw, on the map: each object placed straight ahead of the camera
at its distance, from where the camera sits on the robot (``/tf_static``) and the robot's pose;
unknown distances left out, absurd ones and absurd counts warned of; sent to pages that show the
map as ``det``, at most 5 a second per robot, and the detector listened to only while a page
shows the map."""

from __future__ import annotations

import math
import time
from functools import partial

import pytest

from cyborg.interfaces import detector
from cyborg.monitor.detection_wire import (
    DETECTION_LIMIT,
    detections_wire,
    place,
    predictions_wire,
)
from cyborg.monitor.robot_hub import DETECTIONS_INTERVAL
from tests.monitor.monitor_protocol import local_client, next_json
from tests.monitor.robot_messages import detections, pose, predictions, transforms
from tests.monitor.test_robot_protocol import (
    _followed,
    _gather,
    _map_on,
    _subscribed,
    _until,
    robot_bus,
)
from tests.running_system import wait_until


def test_objects_are_read_with_their_class_score_and_distance() -> None:
    found, frame, warnings = detections_wire(detections(("person", 0.934, 2.5),
                                                        ("chair", 0.5, math.nan)))
    assert (found, frame, warnings) == (
        [{"label": "person", "score": 0.93, "r": 2.5}], "camera_left", []), \
        "an unknown distance (NaN) is nothing to place, and no fault"
    assert predictions_wire(predictions(("dog", 1.7, 1.0), frame="cam"))[:2] == (
        [{"label": "dog", "score": 1.0, "r": 1.0}], "cam"), "scores clamped to 0-1"


def test_objects_lie_straight_ahead_of_the_camera_at_their_distance() -> None:
    found = [{"label": "person", "score": 0.9, "r": 2.0}]
    assert place(found, [1.0, 1.0, math.pi / 2], None) == [
        {"label": "person", "score": 0.9, "p": [1.0, 3.0]}], "from the robot's centre"
    mounted = place(found, [1.0, 1.0, math.pi / 2], [0.5, 0.0, -math.pi / 2])
    assert mounted[0]["p"] == pytest.approx([3.0, 1.5]), "a camera 0.5 m ahead, looking right"


@pytest.mark.parametrize(("distance", "said"), [(math.inf, "at inf m"), (-1.0, "at -1 m"),
                                                (150.0, "at 150 m")])
def test_an_absurd_distance_leaves_the_object_out_with_a_warning(distance: float,
                                                                 said: str) -> None:
    found, _frame, warnings = detections_wire(detections(("person", 0.9, distance),
                                                         ("cup", 0.8, 1.0)))
    assert [item["label"] for item in found] == ["cup"]
    assert warnings == [f"detections: object 0 {said}, not 0 to 100 m; left out"]


def test_a_score_that_is_not_a_number_leaves_the_object_out() -> None:
    found, _frame, warnings = predictions_wire(predictions(("cup", math.nan, 1.0)))
    assert found == [] and warnings == ["detections: object 0's score is nan; left out"]


def test_at_most_200_objects_of_a_message_are_placed_and_warnings_are_summed_up() -> None:
    many = [("person", 0.9, 1.0 + index / 100) for index in range(DETECTION_LIMIT + 50)]
    found, _frame, warnings = detections_wire(detections(*many))
    assert len(found) == DETECTION_LIMIT
    assert warnings == ["detections: 250 objects in one message; the first 200 placed"]
    bad = [("person", 0.9, -1.0)] * 10
    _found, _frame, warnings = detections_wire(detections(*bad))
    assert len(warnings) == 4 and warnings[-1] == "detections: and 7 more objects left out"


def test_a_page_that_shows_the_map_gets_the_detections_placed_at_most_5_a_second() -> None:
    with robot_bus() as (monitor, fake), local_client(monitor.app) as client, \
            client.websocket_connect("/ws") as socket:
        graph = monitor.node.context.graph
        name = detector.DETECTIONS.full_name("/robot1/detector")
        fake.tf_static.publish(transforms(("base_link", "camera_left", 0.2, 0.0, 0.0)))
        _map_on(socket)
        _followed(monitor, fake)
        wait_until(partial(_subscribed, graph, name), 10.0, "the detector listened to")
        wait_until(partial(_subscribed, graph, "/tf_static"), 10.0, "/tf_static")
        fake.pose.publish(pose(1.0, 2.0, 0.0))
        _until(socket, "rs")
        fake.detections.publish(detections(("person", 0.91, 3.0), ("chair", 0.4, math.nan),
                                           ("cup", 0.7, math.inf)))
        got = _gather(socket, {"det": None, "robot_warn": None})
        assert got["det"] == {"t": "det", "ns": "/robot1", "id": 1, "d": [
            {"label": "person", "score": 0.91, "p": [4.2, 2.0]}]}
        assert got["robot_warn"]["kind"] == "detections"
        assert got["robot_warn"]["message"] == (
            "detections: object 2 at inf m, not 0 to 100 m; left out")
        fake.predictions.publish(predictions(("dog", 0.9, 1.0)))  # the same, the 2018 way
        start, sent, ids = time.monotonic(), 0, []
        while time.monotonic() - start < 1.5:
            sent += 1
            fake.detections.publish(detections(("person", 0.9, 1.0 + sent / 100)))
            time.sleep(0.02)
        while (message := next_json(socket))["t"] != "det" or message["id"] < sent + 1:
            if message["t"] == "det":
                ids.append(message["id"])
                assert message["d"][0]["label"] == "person", "predictions ignored meanwhile"
        elapsed = time.monotonic() - start
        assert len(ids) + 1 <= elapsed / DETECTIONS_INTERVAL + 2, f"{len(ids)} in {elapsed}"
        assert message["d"][0]["p"] == [round(1.2 + 1.0 + sent / 100, 2), 2.0], \
            "the newest always goes, last"
        socket.send_json({"t": "map", "on": False})
        wait_until(lambda: not _subscribed(graph, name), 10.0, "the detector let go")


def test_a_detector_of_2018_is_followed_through_its_predictions() -> None:
    with robot_bus() as (monitor, fake), local_client(monitor.app) as client, \
            client.websocket_connect("/ws") as socket:
        _map_on(socket)
        _followed(monitor, fake)
        name = detector.PREDICTIONS.full_name("/robot1/detector")
        wait_until(partial(_subscribed, monitor.node.context.graph, name), 10.0, name)
        fake.pose.publish(pose(0.0, 0.0, math.pi))
        _until(socket, "rs")
        fake.predictions.publish(predictions(("person", 0.8, 2.0), frame="nowhere"))
        assert _until(socket, "det")["d"] == [{"label": "person", "score": 0.8,
                                               "p": [-2.0, 0.0]}], \
            "no transform to its frame: from the robot's centre, facing forward"


def test_the_detector_of_a_robot_is_where_cyborg_up_starts_it() -> None:
    assert detector.detector_of_robot("/cyborg") == detector.DETECTOR_NAMESPACE
    assert detector.detector_of_robot("/robot2") == "/robot2/detector"
