"""What the robot's tracker follows, on the map: each object of its ``objects`` checked and made
small (id, label, position, velocity, confidence, age on the message's stamp, times seen);
positions off the map, absurd velocities and confidences, repeated ids, other frames and
floods refused or mended with a warning; sent to pages that show the map as ``obj``, at most 5
a second per robot, the newest last, and the topic listened to only while a page shows the
map."""

from __future__ import annotations

import math
import time
from functools import partial

import pytest

from cyborg.interfaces import perception
from cyborg.monitor import robot_hub
from cyborg.monitor.object_wire import LABEL_LIMIT, OBJECT_LIMIT, objects_wire
from cyborg.monitor.robot_hub import OBJECTS_INTERVAL
from tests.monitor.monitor_protocol import local_client, next_json
from tests.monitor.robot_messages import pose, tracked, tracked_objects
from tests.monitor.test_robot_protocol import (
    _followed,
    _gather,
    _map_on,
    _subscribed,
    _until,
    robot_bus,
)
from tests.running_system import wait_until


def test_each_object_is_read_with_its_place_speed_confidence_age_and_sightings() -> None:
    found, warnings = objects_wire(tracked_objects(
        tracked(7, "person", (3.2149, -1.0501), (0.8012, -0.2), confidence=0.7777,
                last_seen=9.6, times_seen=12),
        tracked(8, "chair", (0.0, 5.0), last_seen=4.0, times_seen=1), now=10.0))
    assert warnings == []
    assert found == [
        {"id": 7, "label": "person", "x": 3.21, "y": -1.05, "vx": 0.8, "vy": -0.2,
         "conf": 0.78, "age": 0.4, "seen": 12},
        {"id": 8, "label": "chair", "x": 0.0, "y": 5.0, "vx": 0.0, "vy": 0.0, "conf": 0.8,
         "age": 6.0, "seen": 1}]


def test_a_fleets_map_frame_is_the_map_and_any_other_frame_is_refused() -> None:
    assert objects_wire(tracked_objects(tracked(1), frame="robot2/map"))[0] is not None
    found, warnings = objects_wire(tracked_objects(tracked(1), frame="base_link"))
    assert found is None
    assert warnings == ["objects: frame 'base_link', not 'map'; message ignored"]


@pytest.mark.parametrize(("x", "y"), [(math.nan, 1.0), (1.0, math.inf), (-math.inf, 0.0),
                                      (10_001.0, 0.0), (7_100.0, 7_100.0)])
def test_an_object_that_is_not_on_the_map_is_left_out_with_a_warning(x: float,
                                                                     y: float) -> None:
    found, warnings = objects_wire(tracked_objects(tracked(1, at=(x, y)), tracked(2)))
    assert found is not None and [item["id"] for item in found] == [2]
    assert len(warnings) == 1 and warnings[0].startswith("objects: object 0 at (")
    assert warnings[0].endswith("not a place on the map; left out")


def test_odd_confidences_velocities_labels_and_ids_are_mended_or_left_out() -> None:
    found, warnings = objects_wire(tracked_objects(
        tracked(1, confidence=math.nan),
        tracked(2, "x" * 500, velocity=(math.inf, 0.0), confidence=1.7),
        tracked(3, velocity=(0.0, -25.0), confidence=-0.5, last_seen=12.0),
        tracked(2, "again")))
    assert found is not None
    assert [(item["id"], item["conf"], item["vx"], item["vy"], item["age"]) for item in found] \
        == [(2, 1.0, 0.0, 0.0, 0.0), (3, 0.0, 0.0, 0.0, 0.0)], \
        "clamped to 0-1, drawn at rest, seen after the stamp: age 0"
    assert found[0]["label"] == "x" * LABEL_LIMIT
    assert warnings == ["objects: object 0's confidence is nan; left out",
                        "objects: object 1's velocity (inf, 0) is not a speed; drawn at rest",
                        "objects: object 2's velocity (0, -25) is not a speed; drawn at rest",
                        "objects: object 3 repeats id 2; left out"]


def test_at_most_200_objects_are_read_and_a_message_gives_at_most_4_warnings() -> None:
    many = [tracked(index, at=(index / 10, 0.0)) for index in range(OBJECT_LIMIT + 50)]
    found, warnings = objects_wire(tracked_objects(*many))
    assert found is not None and len(found) == OBJECT_LIMIT and found[-1]["id"] == 199
    assert warnings == ["objects: 250 objects in one message; the first 200 drawn"]
    bad = [tracked(index, at=(math.nan, 0.0)) for index in range(10)]
    found, warnings = objects_wire(tracked_objects(*bad))
    assert found == [] and len(warnings) == 4
    assert warnings[-1] == "objects: and 7 more warnings"


def test_a_page_that_shows_the_map_gets_the_objects_at_most_5_a_second() -> None:
    with robot_bus() as (monitor, fake), local_client(monitor.app) as client, \
            client.websocket_connect("/ws") as socket:
        graph = monitor.node.context.graph
        name = perception.OBJECTS.full_name("/robot1")
        assert not _subscribed(graph, name), "nobody looks: the tracker is not listened to"
        _map_on(socket)
        _followed(monitor, fake)
        wait_until(partial(_subscribed, graph, name), 10.0, "the objects listened to")
        fake.pose.publish(pose(1.0, 2.0, 0.0))
        _until(socket, "rs")
        fake.objects.publish(tracked_objects(
            tracked(4, "person", (2.5, 3.0), (1.0, 0.0), last_seen=9.5),
            tracked(5, "person", (math.nan, 3.0)), now=10.25))
        got = _gather(socket, {"obj": None, "robot_warn": None})
        assert got["obj"] == {"t": "obj", "ns": "/robot1", "id": 1, "stamp": 10.25, "o": [
            {"id": 4, "label": "person", "x": 2.5, "y": 3.0, "vx": 1.0, "vy": 0.0,
             "conf": 0.8, "age": 0.75, "seen": 3}]}
        assert got["robot_warn"]["kind"] == "objects"
        assert got["robot_warn"]["message"] == (
            "objects: object 1 at (nan, 3), not a place on the map; left out")
        start, sent, ids = time.monotonic(), 1, []
        while time.monotonic() - start < 1.5:
            sent += 1
            fake.objects.publish(tracked_objects(tracked(4, at=(2.5 + sent / 100, 3.0)),
                                                 now=10.0 + sent))
            time.sleep(0.02)
        while (message := next_json(socket))["t"] != "obj" or message["id"] < sent:
            if message["t"] == "obj":
                ids.append(message["id"])
        elapsed = time.monotonic() - start
        assert len(ids) + 1 <= elapsed / OBJECTS_INTERVAL + 2, f"{len(ids)} in {elapsed}"
        assert message["o"][0]["x"] == round(2.5 + sent / 100, 2), "the newest goes, last"
        socket.send_json({"t": "map", "on": False})
        wait_until(lambda: not _subscribed(graph, name), 10.0, "the objects let go")


def test_a_page_that_starts_to_look_gets_the_objects_only_while_they_are_fresh(
        monkeypatch: pytest.MonkeyPatch) -> None:
    with robot_bus() as (monitor, fake), local_client(monitor.app) as client, \
            client.websocket_connect("/ws") as first:
        _map_on(first)
        _followed(monitor, fake)
        wait_until(partial(_subscribed, monitor.node.context.graph,
                           perception.OBJECTS.full_name("/robot1")), 10.0, "objects")
        fake.pose.publish(pose(1.0, 2.0, 0.0))
        fake.objects.publish(tracked_objects(tracked(9, "dog", (4.0, 4.0))))
        _until(first, "obj")
        with client.websocket_connect("/ws") as second:
            _map_on(second)
            assert _until(second, "obj")["o"][0]["label"] == "dog", "a fresh list is resent"
        monkeypatch.setattr(robot_hub, "OBJECTS_KEPT", 0.0)
        with client.websocket_connect("/ws") as third:
            _map_on(third)
            third.send_json({"t": "ping", "req": 5})
            kinds = []
            while (message := next_json(third))["t"] != "pong":
                kinds.append(message["t"])
            assert "rs" in kinds and "obj" not in kinds, f"a stale list is not resent: {kinds}"
