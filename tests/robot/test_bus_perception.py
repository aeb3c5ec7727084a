"""The robot client's eyes, voice and speeds on the bus: objects read with their ages, a list
that stops coming goes stale, say and cmd_vel published."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest

from cyborg.bus import BusConfig, Context, Node
from cyborg.bus.msgs.builtin_interfaces.msg import Time
from cyborg.bus.msgs.cyborg_msgs.msg import TrackedObject, TrackedObjects
from cyborg.bus.msgs.geometry_msgs.msg import Point, Vector3
from cyborg.bus.msgs.std_msgs.msg import Header
from cyborg.interfaces import perception, robot
from cyborg.robot.bus_perception import STALE_AFTER, BusPerception, seen_objects
from tests.bus.bus_peer import wait_for


@pytest.fixture
def bus() -> Iterator[Context]:
    with Context(BusConfig.isolated()) as context:
        yield context


def objects_message(stamp: float, last_seen: float, x: float = 2.0) -> TrackedObjects:
    def time(seconds: float) -> Time:
        return Time(sec=int(seconds), nanosec=int(seconds % 1 * 1e9))
    item = TrackedObject(id=4, label="person", confidence=0.8, position=Point(x=x, y=1.0, z=0.0),
                         velocity=Vector3(x=0.5, y=0.0, z=0.0), last_seen=time(last_seen),
                         times_seen=9, distance=2.2, bearing=0.4)
    return TrackedObjects(header=Header(stamp=time(stamp), frame_id="map"), objects=[item])


def test_an_objects_message_reads_as_seen_objects_aged_by_its_stamp() -> None:
    (seen,) = seen_objects(objects_message(stamp=12.5, last_seen=12.0))
    assert (seen.id, seen.label, seen.x, seen.y, seen.vx, seen.times_seen) == (
        4, "person", 2.0, 1.0, 0.5, 9)
    assert seen.age == pytest.approx(0.5)
    assert seen_objects(objects_message(12.5, 12.0, x=float("nan"))) == []


def test_the_list_arrives_on_the_bus_and_goes_stale_when_it_stops(bus: Context) -> None:
    wall = [100.0]
    eyes = BusPerception(Node("bt", "/cyborg", context=bus), "/cyborg", wall=lambda: wall[0])
    assert eyes.objects() == []
    tracker = perception.OBJECTS.publisher(Node("tracker", "/cyborg", context=bus))

    def heard() -> bool:
        tracker.publish(objects_message(5.0, 4.9))
        return bool(eyes.objects())
    assert wait_for(heard, 20)
    assert [item.id for item in eyes.objects()] == [4]
    wall[0] += STALE_AFTER + 0.1
    assert eyes.objects() == [], "the tracker went quiet: nothing is in sight any more"


def test_say_and_drive_are_published_under_the_robot(bus: Context) -> None:
    eyes = BusPerception(Node("bt", "/elsewhere", context=bus), "/robot2")
    listener = Node("listener", "/robot2", context=bus)
    said: list[Any] = []
    speeds: list[Any] = []
    perception.SAY.subscription(listener, said.append)
    robot.CMD_VEL.subscription(listener, speeds.append)

    def heard() -> bool:
        eyes.say("Hello!")
        eyes.drive(0.2, -0.5)
        return bool(said and speeds)
    assert wait_for(heard, 20)
    assert said[-1].data == "Hello!"
    assert (speeds[-1].linear.x, speeds[-1].angular.z) == (0.2, -0.5)
