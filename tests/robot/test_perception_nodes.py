"""The perception nodes against a scripted robot: ObjectDetected, ClosestObject, FaceObject,
ApproachObject and Say."""

from __future__ import annotations

import math
from typing import Any

import pytest
from hypothesis import given
from hypothesis import strategies as st

from cyborg.bt import ERROR, FAILURE, RUNNING, SUCCESS, ManualClock, TreeLoadError
from cyborg.nav.geometry import Pose2D
from cyborg.robot.perceiving import SeenObject
from cyborg.robot.say import Template
from tests.builders import N
from tests.robot.fake_robot import FakeRobot, robot_tree


def thing(label: str, x: float, y: float, *, id: int = 1, confidence: float = 0.9,
          age: float = 0.1) -> SeenObject:
    return SeenObject(id, label, confidence, x, y, 0.0, 0.0, age, 5, math.nan, math.nan)


def at_origin(*objects: SeenObject) -> FakeRobot:
    return FakeRobot(pose=Pose2D(0.0, 0.0, 0.0), seen=list(objects))


# ---------------------------------------------------------------------------- ObjectDetected
def test_object_detected_needs_the_label_near_sure_and_fresh() -> None:
    robot = at_origin(thing("chair", 1.0, 0.0), thing("person", 3.0, 0.0))
    tree = robot_tree(N("ObjectDetected", label="person", maxDistance=2.0), robot)
    assert tree.tick().status is FAILURE  # the person is 3 m away, the chair is no person
    robot.seen = [thing("person", 1.5, 1.0)]
    assert tree.tick().status is SUCCESS
    robot.seen = [thing("person", 1.5, 1.0, confidence=0.3)]
    assert tree.tick().status is FAILURE
    robot.seen = [thing("person", 1.5, 1.0, age=1.5)]
    assert tree.tick().status is FAILURE
    robot.seen = []
    assert tree.tick().status is FAILURE


def test_object_detected_measures_from_the_robot_where_it_is_now() -> None:
    robot = at_origin(thing("person", 10.0, 0.0))
    tree = robot_tree(N("ObjectDetected", label="person", maxDistance=2.0), robot)
    assert tree.tick().status is FAILURE
    robot.pose = Pose2D(9.0, 0.5, 2.0)
    assert tree.tick().status is SUCCESS


@pytest.mark.parametrize("properties", [{"maxDistance": -1}, {"minConfidence": -0.1},
                                        {"maxAge": -2}])
def test_object_detected_refuses_negative_limits_at_load(properties: dict[str, Any]) -> None:
    with pytest.raises(TreeLoadError, match=next(iter(properties))):
        robot_tree(N("ObjectDetected", label="person", **properties), at_origin())


# ---------------------------------------------------------------------------- ClosestObject
def test_closest_object_writes_the_nearest_ones_bearing_distance_and_position() -> None:
    robot = at_origin(thing("person", 4.0, 0.0, id=7), thing("person", 0.0, 2.0, id=8),
                      thing("dog", 0.5, 0.0, id=9))
    tree = robot_tree(N("ClosestObject", label="person", key="who"), robot)
    assert tree.tick().status is SUCCESS
    entry = tree.blackboard["who"]
    assert (entry["id"], entry["label"], entry["x"], entry["y"]) == (8, "person", 0.0, 2.0)
    assert entry["distance"] == pytest.approx(2.0)
    assert entry["bearing"] == pytest.approx(math.pi / 2)  # to the left
    robot.seen = []
    assert tree.tick().status is FAILURE
    assert tree.blackboard["who"] is None


# ---------------------------------------------------------------------------- FaceObject
def test_face_object_turns_toward_it_until_within_tolerance_then_stops() -> None:
    robot, clock = at_origin(thing("person", 0.0, 2.0)), ManualClock()  # 90° to the left
    tree = robot_tree(N("FaceObject", label="person", tolerance=0.1), robot, clock)
    assert tree.tick().status is RUNNING
    linear, angular = robot.drives[-1]
    assert linear == 0.0 and angular > 0, "turn left, on the spot"
    robot.pose = Pose2D(0.0, 0.0, math.pi / 2 - 0.3)
    assert tree.tick().status is RUNNING
    assert 0 < robot.drives[-1][1] < angular, "slower as the bearing closes"
    robot.pose = Pose2D(0.0, 0.0, math.pi / 2 - 0.05)
    assert tree.tick().status is SUCCESS
    assert robot.drives[-1] == (0.0, 0.0)


def test_face_object_turns_right_for_an_object_on_the_right() -> None:
    robot = at_origin(thing("person", 1.0, -1.0))
    tree = robot_tree(N("FaceObject", label="person"), robot)
    assert tree.tick().status is RUNNING
    assert robot.drives[-1][1] < 0


def test_face_object_fails_when_its_object_is_lost_and_stops_turning() -> None:
    robot = at_origin(thing("person", 0.0, 2.0, id=3), thing("person", 0.0, -5.0, id=4))
    tree = robot_tree(N("FaceObject", label="person"), robot)
    assert tree.tick().status is RUNNING
    robot.seen = [thing("person", 0.0, -5.0, id=4)]  # another person is no reason to go on
    assert tree.tick().status is FAILURE
    assert robot.drives[-1] == (0.0, 0.0)
    assert "lost the person 3" in tree.nodes[1].reason  # type: ignore[attr-defined]


def test_face_object_fails_at_once_with_nothing_in_sight_and_sends_nothing() -> None:
    robot = at_origin()
    tree = robot_tree(N("FaceObject", label="person"), robot)
    assert tree.tick().status is FAILURE
    assert robot.drives == []


def test_halting_face_object_stops_the_turn() -> None:
    robot = at_origin(thing("person", 0.0, 2.0))
    tree = robot_tree(N("FaceObject", label="person"), robot)
    assert tree.tick().status is RUNNING
    tree.halt()
    assert robot.drives[-1] == (0.0, 0.0)


# ---------------------------------------------------------------------------- ApproachObject
def test_approach_object_drives_up_to_the_stop_distance() -> None:
    robot = at_origin(thing("person", 3.0, 0.2))
    tree = robot_tree(N("ApproachObject", label="person", stopDistance=1.0), robot)
    assert tree.tick().status is RUNNING
    linear, angular = robot.drives[-1]
    assert linear > 0 and angular > 0
    robot.pose = Pose2D(2.1, 0.1, 0.0)
    assert tree.tick().status is SUCCESS
    assert robot.drives[-1] == (0.0, 0.0)


def test_approach_object_turns_first_when_the_object_is_behind() -> None:
    robot = at_origin(thing("person", -3.0, 0.1))
    tree = robot_tree(N("ApproachObject", label="person"), robot)
    assert tree.tick().status is RUNNING
    assert robot.drives[-1][0] == 0.0 and robot.drives[-1][1] != 0.0


def test_halting_approach_object_stops_the_robot() -> None:
    robot = at_origin(thing("person", 3.0, 0.0))
    tree = robot_tree(N("ApproachObject", label="person"), robot)
    tree.tick()
    tree.halt()
    assert robot.drives[-1] == (0.0, 0.0)


# ---------------------------------------------------------------------------- Say
def test_say_fills_placeholders_from_the_blackboard() -> None:
    robot = at_origin(thing("person", 0.0, 2.0))
    tree = robot_tree(N("Sequence", N("ClosestObject", label="person"),
                        N("Say", text="Hello {closest.label}, {closest.distance:.1f} m away! "
                                      "{{braces}}")), robot)
    assert tree.tick().status is SUCCESS
    assert robot.said == ["Hello person, 2.0 m away! {braces}"]


def test_say_fails_without_speaking_when_an_entry_is_missing() -> None:
    robot = at_origin()
    tree = robot_tree(N("Say", text="Hello {visitor}!"), robot)
    assert tree.tick().status is FAILURE
    assert robot.said == []
    assert "visitor" in tree.nodes[1].reason  # type: ignore[attr-defined]


@pytest.mark.parametrize("text", ["Hello {", "Hello {}", "Hi {0}", "Hi {name!r}",
                                  "Hi {a b}", "Hi {a[0]}", "   "])
def test_a_bad_template_is_refused_at_load_naming_the_node(text: str) -> None:
    with pytest.raises(TreeLoadError, match="Say"):
        robot_tree(N("Say", text=text), at_origin())


@given(st.text(alphabet=st.characters(blacklist_characters="{}"), max_size=40))
def test_text_without_braces_is_said_as_it_is(text: str) -> None:
    assert Template.parse(text).render({}) == text


def test_a_robot_that_cannot_see_is_an_error_naming_the_node_and_what_it_lacks(
        caplog: pytest.LogCaptureFixture) -> None:
    class Blind:
        pose = Pose2D(0.0, 0.0)

    tree = robot_tree(N("ObjectDetected", label="person"), Blind())  # type: ignore[arg-type]
    assert tree.tick().status is ERROR
    assert "ObjectDetected needs a robot that sees and speaks" in caplog.text
    assert "objects, say, drive" in caplog.text
