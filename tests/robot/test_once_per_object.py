"""OncePerObject: a greeting under a Priority happens once per person, not on every tick."""

from __future__ import annotations

import math
from typing import Any

import pytest

from cyborg.bt import FAILURE, RUNNING, SUCCESS, ManualClock, TreeLoadError
from cyborg.nav.geometry import Pose2D
from cyborg.robot.once_per_object import OncePerObject
from cyborg.robot.perceiving import SeenObject
from tests.builders import N
from tests.robot.fake_robot import FakeRobot, robot_tree


def person(id: int, x: float = 1.5, y: float = 0.0) -> SeenObject:
    return SeenObject(id, "person", 0.9, x, y, 0.0, 0.0, 0.1, 5, math.nan, math.nan)


def greeting(**properties: Any) -> N:
    """ClosestObject, then once per object: face them and say hello."""
    return N("Sequence",
             N("ClosestObject", label="person", key="visitor"),
             N("OncePerObject", N("Sequence",
                                  N("FaceObject", label="person"),
                                  N("Say", text="Hello {visitor.id}!")),
               key="visitor", **properties))


def test_each_person_is_greeted_once_within_the_cooldown() -> None:
    robot, clock = FakeRobot(pose=Pose2D(0.0, 0.0, 0.0), seen=[person(1)]), ManualClock()
    tree = robot_tree(greeting(seconds=60, gap=10), robot, clock)
    assert tree.tick().status is SUCCESS
    assert robot.said == ["Hello 1!"]
    for _ in range(5):  # the person stays in front of the robot
        clock.advance(1.0)
        assert tree.tick().status is FAILURE
    robot.seen = [person(2, x=4.5)]  # someone else, 5 s after the first greeting: too soon
    assert tree.tick().status is FAILURE
    clock.advance(5.0)
    assert tree.tick().status is SUCCESS
    assert robot.said == ["Hello 1!", "Hello 2!"]
    robot.seen = [person(1)]  # the first again, 20 s after their greeting
    clock.advance(10.0)
    assert tree.tick().status is FAILURE
    clock.advance(40.0)  # 60 s after their greeting
    assert tree.tick().status is SUCCESS
    assert robot.said[-1] == "Hello 1!" and len(robot.said) == 3


def test_without_a_gap_people_are_greeted_one_after_the_other() -> None:
    robot, clock = FakeRobot(pose=Pose2D(0.0, 0.0, 0.0), seen=[person(1)]), ManualClock()
    tree = robot_tree(greeting(gap=0), robot, clock)
    assert tree.tick().status is SUCCESS
    robot.seen = [person(2, x=4.5)]
    assert tree.tick().status is SUCCESS
    assert robot.said == ["Hello 1!", "Hello 2!"]


def test_a_new_id_where_someone_greeted_was_last_seen_is_that_someone() -> None:
    robot, clock = FakeRobot(pose=Pose2D(0.0, 0.0, 0.0), seen=[person(1)]), ManualClock()
    tree = robot_tree(greeting(gap=0), robot, clock)
    assert tree.tick().status is SUCCESS
    for step in range(1, 4):  # they walk away, seen, 1.5 m a second
        clock.advance(1.0)
        robot.seen = [person(1, x=1.5 + 1.5 * step)]
        assert tree.tick().status is FAILURE
    clock.advance(3.0)  # lost, and found again as a new object near where last seen
    robot.seen = [person(5, x=7.0)]
    assert tree.tick().status is FAILURE, "5.5 m from the greeting, 1 m from where last seen"
    assert robot.said == ["Hello 1!"]
    clock.advance(54.0)  # 60 s after the greeting of the person they are
    assert tree.tick().status is SUCCESS
    assert robot.said == ["Hello 1!", "Hello 5!"]


def test_with_near_0_only_ids_count() -> None:
    robot, clock = FakeRobot(pose=Pose2D(0.0, 0.0, 0.0), seen=[person(1)]), ManualClock()
    tree = robot_tree(greeting(gap=0, near=0), robot, clock)
    assert tree.tick().status is SUCCESS
    robot.seen = [person(2)]  # a new id at the same place
    assert tree.tick().status is SUCCESS
    assert robot.said == ["Hello 1!", "Hello 2!"]


def test_a_greeting_that_fails_is_not_remembered() -> None:
    robot, clock = FakeRobot(pose=Pose2D(0.0, 0.0, 0.0), seen=[person(1)]), ManualClock()
    tree = robot_tree(N("OncePerObject", N("Scripted", id="act", script="FS"), key="visitor"),
                      robot, clock)
    tree.blackboard["visitor"] = {"id": 1}
    assert tree.tick().status is FAILURE  # the child failed: try again
    assert tree.tick().status is SUCCESS
    assert tree.tick().status is FAILURE  # done: not again
    ticked = [uid for event, uid in tree.blackboard["events"] if event == "tick"]
    assert ticked == ["act", "act"]


def test_the_object_is_chosen_when_the_activation_begins() -> None:
    robot, clock = FakeRobot(pose=Pose2D(0.0, 0.0, 0.0)), ManualClock()
    tree = robot_tree(N("OncePerObject", N("Scripted", script="RS"), key="visitor", gap=0),
                      robot, clock)
    tree.blackboard["visitor"] = {"id": 1}
    assert tree.tick().status is RUNNING
    tree.blackboard["visitor"] = {"id": 2}  # someone else became the closest meanwhile
    assert tree.tick().status is SUCCESS
    node = next(node for node in tree if isinstance(node, OncePerObject))
    assert set(node.done_lately()) == {1}, "the one it began with was done"


@pytest.mark.parametrize("entry", [None, "someone", {"label": "person"}, {"id": None},
                                   {"id": True}])
def test_an_entry_without_an_object_fails_without_ticking_the_child(entry: object) -> None:
    robot = FakeRobot(pose=Pose2D(0.0, 0.0, 0.0))
    tree = robot_tree(N("OncePerObject", N("Scripted", id="act"), key="visitor"), robot)
    if entry is not None:
        tree.blackboard["visitor"] = entry
    assert tree.tick().status is FAILURE
    assert not [uid for event, uid in tree.blackboard["events"] if event == "tick"]
    node = next(node for node in tree if isinstance(node, OncePerObject))
    assert "'visitor' holds no object" in node.reason


class RestartingClock(ManualClock):
    """A manual clock that can go back, as a restarted simulation's does."""

    def restart(self, now: float) -> None:
        self._now = now


def test_a_clock_that_goes_back_forgets_who_was_greeted() -> None:
    robot, clock = FakeRobot(pose=Pose2D(0.0, 0.0, 0.0)), RestartingClock(start=100.0)
    tree = robot_tree(N("OncePerObject", N("Scripted"), key="visitor"), robot, clock)
    tree.blackboard["visitor"] = {"id": 1}
    assert tree.tick().status is SUCCESS
    clock.advance(1.0)
    assert tree.tick().status is FAILURE
    clock.restart(5.0)  # a restarted simulation
    assert tree.tick().status is SUCCESS


@pytest.mark.parametrize("properties", [{"key": ""}, {"seconds": -1}, {"gap": math.nan},
                                        {"gap": "soon"}, {"near": -0.5}])
def test_bad_properties_are_refused_at_load_naming_them(properties: dict[str, Any]) -> None:
    with pytest.raises(TreeLoadError, match=next(iter(properties))):
        robot_tree(N("OncePerObject", N("Succeeder"), **properties), FakeRobot())
