"""The simulator's subscription to its robot's objects: people become temporary obstacles of the
navigator, other labels, other frames and positions that are not numbers do not."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from cyborg.bus import BusConfig, Context, Node
from cyborg.bus.component import LaunchError, NodeSpec
from cyborg.bus.msgs.builtin_interfaces.msg import Time
from cyborg.bus.msgs.cyborg_msgs.msg import TrackedObject, TrackedObjects
from cyborg.bus.msgs.geometry_msgs.msg import Point, Vector3
from cyborg.bus.msgs.std_msgs.msg import Header
from cyborg.interfaces import perception
from cyborg.sim.component import RunningSimulator, start
from tests.bus.bus_peer import wait_for
from tests.small_maps import corridor_map, write


def tracked(ident: int, label: str, x: float, y: float, last_seen: float) -> TrackedObject:
    return TrackedObject(id=ident, label=label, confidence=0.9, position=Point(x=x, y=y, z=0.0),
                         velocity=Vector3(x=0.0, y=0.0, z=0.0), last_seen=stamp(last_seen),
                         times_seen=5, distance=2.0, bearing=0.0)


def stamp(seconds: float) -> Time:
    return Time(sec=int(seconds), nanosec=int(seconds % 1 * 1e9))


def objects(items: list[TrackedObject], at: float, frame: str = "map") -> TrackedObjects:
    return TrackedObjects(header=Header(stamp=stamp(at), frame_id=frame), objects=items)


@pytest.fixture
def bus() -> Iterator[Context]:
    with Context(BusConfig.isolated()) as context:
        yield context


def simulator(bus: Context, folder: Path, **parameters: Any) -> RunningSimulator:
    map_path = write(folder, "corridor.map", corridor_map(2.0))
    running = start(bus, NodeSpec("simulator", "arnl", "/cyborg",
                                  {"map": str(map_path), "speed": 1.0, **parameters}))
    assert isinstance(running, RunningSimulator)
    return running


def test_people_on_the_objects_topic_become_the_navigators_obstacles(
        bus: Context, tmp_path: Path) -> None:
    running = simulator(bus, tmp_path)
    try:
        tracker = perception.OBJECTS.publisher(Node("tracker", "/cyborg", context=bus))
        navigator = running.loop.simulator.navigator
        listed = [tracked(1, "person", 5.0, 1.0, last_seen=99.5),
                  tracked(2, "chair", 6.0, 1.0, last_seen=100.0),
                  tracked(3, "person", float("nan"), 1.0, last_seen=100.0)]

        def heard() -> bool:
            tracker.publish(objects(listed, at=100.0))
            return len(navigator.obstacles) > 0
        assert wait_for(heard, 20)
        with running.loop.lock:
            now = running.loop.simulator.time
            discs = navigator.obstacles.discs(now)
        assert discs[:, :2].tolist() == [[5.0, 1.0]], \
            "the person only: chairs are not people, and a position must be a number"
        assert discs[0, 2] == pytest.approx(navigator.obstacles.settings.keep_out)
    finally:
        running.stop()


def test_every_label_when_asked_and_lists_in_another_frame_ignored(
        bus: Context, tmp_path: Path) -> None:
    running = simulator(bus, tmp_path, obstacle_labels=[""])
    try:
        tracker = perception.OBJECTS.publisher(Node("tracker", "/cyborg", context=bus))
        navigator = running.loop.simulator.navigator

        def heard(ident: int) -> bool:
            tracker.publish(objects([tracked(ident, "chair", 4.0, ident, 10.0)], 10.0))
            with running.loop.lock:
                return ident in navigator.obstacles.discs(running.loop.simulator.time)[:, 1]
        assert wait_for(lambda: heard(1), 20), "any label is an obstacle with an empty string"
        tracker.publish(objects([tracked(2, "chair", 4.0, 2.0, 10.0)], 10.0, "odom"))
        assert wait_for(lambda: heard(3), 20)  # in order: the list in odom came before
        with running.loop.lock:
            ys = navigator.obstacles.discs(running.loop.simulator.time)[:, 1].tolist()
        assert 2.0 not in ys, "a list in another frame than map is ignored"
    finally:
        running.stop()


def test_avoiding_objects_can_be_switched_off_and_bad_labels_refuse_the_simulator(
        bus: Context, tmp_path: Path) -> None:
    running = simulator(bus, tmp_path, avoid_objects=False)
    try:
        node = Node("tracker", "/cyborg", context=bus)
        tracker = perception.OBJECTS.publisher(node)
        heard: list[TrackedObjects] = []
        perception.OBJECTS.subscription(node, heard.append)
        navigator = running.loop.simulator.navigator

        def sent() -> bool:
            tracker.publish(objects([tracked(1, "person", 4.0, 1.0, 10.0)], 10.0))
            return len(heard) >= 5
        assert wait_for(sent, 20), "the list travels"
        assert not wait_for(lambda: len(navigator.obstacles) > 0, 0.5), "but nobody plans on it"
    finally:
        running.stop()
    with pytest.raises(LaunchError, match="obstacle_labels"):
        simulator(bus, tmp_path, obstacle_labels=3)
