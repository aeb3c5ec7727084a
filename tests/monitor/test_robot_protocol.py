"""The map's data path end to end, without a browser: a fake robot on an isolated bus publishes
its map, pose, scans, path, path state and battery; a page that opts in with {"t": "map"} gets
map_ref (and can fetch the blob), path, rs at most ~12 a second per robot (scans with the
laser's mount from /tf_static, the footprint once per change), and robot_warn for messages that
cannot be drawn, never an error; the robots list names robots, their trees and their maps; at
most 16 robots are followed."""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from functools import partial
from typing import Any

import numpy as np
import pytest

from cyborg.bus import BusConfig, Context, Node
from cyborg.bus.wire import EntityKind
from cyborg.interfaces import robot, tree_runner
from cyborg.monitor import Monitor
from cyborg.monitor.robot_hub import ROBOT_LIMIT, RS_INTERVAL
from cyborg.monitor.robot_source import MOUNT_GRACE
from tests.monitor.monitor_protocol import local_client, next_json, receive_until
from tests.monitor.robot_messages import (
    BEAMS,
    FakeMapRobot,
    battery,
    footprint,
    map_geometry,
    path,
    pose,
    scan,
    transforms,
)
from tests.monitor.test_map_store import parse_blob
from tests.running_system import wait_until


@contextmanager
def robot_bus() -> Iterator[tuple[Monitor, FakeMapRobot]]:
    """A monitor (not serving) and a fake robot under /robot1 on an isolated bus."""
    with Context(BusConfig.isolated()) as context:
        monitor = Monitor(Node("monitor", "/cyborg", context=context),
                          namespaces=["/robot1/bt"])
        fake = FakeMapRobot(Node("arnl", "/robot1", context=context))
        try:
            yield monitor, fake
        finally:
            monitor.stop()


def _followed(monitor: Monitor, fake: FakeMapRobot) -> None:
    """Waits until the monitor subscribes to ``fake``'s pose and scan (found by discovery)."""
    graph = monitor.node.context.graph
    for name in (robot.POSE.full_name(fake.namespace), robot.SCAN.full_name(fake.namespace)):
        wait_until(partial(_subscribed, graph, name), timeout=10.0,
                   what=f"a subscription to {name}")


def _subscribed(graph: Any, name: str) -> bool:
    return bool(graph.count(name, EntityKind.SUBSCRIPTION) > 0)


def _map_on(socket: Any) -> None:
    socket.send_json({"t": "map", "on": True})


def _until(socket: Any, kind: str, check: Any = None, limit: int = 400) -> dict[str, Any]:
    """The next message of type ``kind`` for which ``check(message)`` holds."""
    for _ in range(limit):
        message = next_json(socket)
        assert message["t"] != "error", message
        if message["t"] == kind and (check is None or check(message)):
            return message
    raise AssertionError(f"no {kind!r} message in {limit} messages")


def _gather(socket: Any, wanted: dict[str, Any], limit: int = 400) -> dict[str, Any]:
    """The first message of each kind in ``wanted`` for which its check holds (None: any), in
    whatever order they come."""
    found: dict[str, Any] = {}
    for _ in range(limit):
        message = next_json(socket)
        assert message["t"] != "error", message
        kind = message["t"]
        if kind in wanted and kind not in found and (wanted[kind] is None
                                                     or wanted[kind](message)):
            found[kind] = message
            if len(found) == len(wanted):
                return found
    raise AssertionError(f"only {sorted(found)} of {sorted(wanted)} in {limit} messages")


class Publishing:
    """Publishes poses (and a scan each) at ``rate`` Hz from a thread until stopped."""

    def __init__(self, fake: FakeMapRobot, rate: float = 50.0) -> None:
        self.fake, self.period = fake, 1.0 / rate
        self.sent = 0
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)

    def _run(self) -> None:
        while not self._stop.is_set():
            self.sent += 1
            self.fake.pose.publish(pose(math.cos(self.sent / 50), math.sin(self.sent / 50),
                                        self.sent / 100))
            self.fake.scan.publish(scan())
            time.sleep(self.period)

    def __enter__(self) -> Publishing:
        self._thread.start()
        return self

    def __exit__(self, *_exc: Any) -> None:
        self._stop.set()
        self._thread.join(5.0)


def test_a_page_that_shows_the_map_gets_the_map_path_and_robot_state() -> None:
    with robot_bus() as (monitor, fake), local_client(monitor.app) as client, \
            client.websocket_connect("/ws") as socket:
        fake.map.publish(map_geometry())
        fake.path.publish(path([(0.0, 0.0), (1.5, 2.25)]))
        fake.state("MOVING_TO_GOAL")
        fake.battery.publish(battery(87.46))
        socket.send_json({"t": "hello"})
        _map_on(socket)
        _followed(monitor, fake)
        fake.pose.publish(pose(1.0, 2.0, 0.5))
        got = _gather(socket, {
            "map_ref": None, "path": None, "rs": lambda m: "bat" in m and "st" in m,
            "robots": lambda m: any(r["map"] for r in m["map_robots"])})
        reference = got["map_ref"]
        assert reference["ns"] == "/robot1" and reference["source"] == "small.map"
        assert reference["counts"] == {"lines": 2, "points": 3, "objects": 2}
        assert reference["url"] == f"/api/map/{reference['key']}"
        blob = client.get(reference["url"])
        assert blob.status_code == 200
        header, _lines, points = parse_blob(blob.content)
        assert header["counts"] == reference["counts"] and len(points) == 3
        assert client.get("/stats").json()["map_fetches"] == 1
        assert got["robots"]["map_robots"] == [{"ns": "/robot1", "tree": "/robot1/bt",
                                                "alive": True, "map": reference["key"]}]
        assert got["path"] == {"t": "path", "ns": "/robot1", "id": 1, "xy": [0, 0, 1500, 2250]}
        state = got["rs"]
        assert state["p"] == [1.0, 2.0, 0.5] and state["pid"] == 1
        assert state["st"] == "MOVING_TO_GOAL"
        assert state["bat"] == {"pct": 87.5, "charging": False, "dock": "UNDOCKED"}
        fake.scan.publish(scan())
        with_scan = _until(socket, "rs", lambda m: "sc" in m)
        assert len(with_scan["sc"]["r"]) == BEAMS and with_scan["seq"] > state["seq"]
        fake.path.publish(path([(3.0, 4.0)]))
        assert _until(socket, "path")["id"] == 2


def test_scans_carry_the_lasers_mount_and_the_footprint_goes_once_per_change() -> None:
    with robot_bus() as (monitor, fake), local_client(monitor.app) as client, \
            client.websocket_connect("/ws") as socket:
        fake.footprint.publish(footprint())
        fake.tf_static.publish(transforms(("base_link", "laser", 0.267, 0.0, 0.0)))
        _map_on(socket)
        _followed(monitor, fake)
        wait_until(lambda: _subscribed(monitor.node.context.graph, "/tf_static"), timeout=10.0)
        fake.pose.publish(pose(1.0, 2.0, 0.5))
        first = _until(socket, "rs", lambda m: "fp" in m)
        assert first["fp"] == [0.3, 0.2, -0.3, 0.2, -0.3, -0.2, 0.3, -0.2]
        fake.scan.publish(scan())
        scanned = _until(socket, "rs", lambda m: "sc" in m)
        assert scanned["sc"]["m"] == [0.267, 0.0, 0.0] and scanned["sc"]["mx"] == 30000
        assert "fp" not in scanned, "the footprint goes once, not in every rs"
        fake.footprint.publish(footprint())  # the same outline again: nothing to send
        fake.footprint.publish(footprint([(0.5, 0.0), (-0.2, 0.3), (-0.2, -0.3)]))
        changed = _until(socket, "rs", lambda m: "fp" in m)
        assert changed["fp"] == [0.5, 0.0, -0.2, 0.3, -0.2, -0.3]
        fake.pose.publish(pose(1.5, 2.0, 0.5))
        assert "fp" not in _until(socket, "rs", lambda m: m["p"][0] == 1.5)
        with client.websocket_connect("/ws") as other:  # a page that starts gets it at once
            _map_on(other)
            assert _until(other, "rs")["fp"] == changed["fp"]


def test_scans_without_a_mount_are_a_warning_after_a_while() -> None:
    with robot_bus() as (monitor, fake), local_client(monitor.app) as client, \
            client.websocket_connect("/ws") as socket:
        _map_on(socket)
        _followed(monitor, fake)
        fake.pose.publish(pose(1.0, 2.0, 0.5))
        for _ in range(MOUNT_GRACE + 5):  # the monitor keeps the newest 2: not in a burst
            fake.scan.publish(scan())
            time.sleep(0.03)
        warning = _until(socket, "robot_warn")
        assert warning["kind"] == "scan" and warning["message"] == (
            "scan: no /tf_static transform to its frame 'laser'; drawn from the robot's centre")
        assert "m" not in _until(socket, "rs", lambda m: "sc" in m)["sc"]


def test_a_fast_robot_is_throttled_to_about_12_states_a_second() -> None:
    with robot_bus() as (monitor, fake), local_client(monitor.app) as client, \
            client.websocket_connect("/ws") as socket, Publishing(fake, 50.0) as publishing:
        _map_on(socket)
        _until(socket, "rs")
        start, count, seqs = time.monotonic(), 0, []
        while time.monotonic() - start < 2.0:
            message = next_json(socket)
            if message["t"] == "rs":
                count += 1
                seqs.append(message["seq"])
        elapsed = time.monotonic() - start
        assert publishing.sent >= 50, "the robot published at all"
        assert count <= elapsed / RS_INTERVAL + 2, f"{count} rs in {elapsed:.2f} s"
        assert count >= 8, f"only {count} rs in {elapsed:.2f} s"
        assert seqs == sorted(seqs)


def test_hostile_robot_messages_become_warnings_not_errors() -> None:
    with robot_bus() as (monitor, fake), local_client(monitor.app) as client, \
            client.websocket_connect("/ws") as socket:
        _map_on(socket)
        _followed(monitor, fake)
        fake.pose.publish(pose(1.0, 1.0, 0.0))
        _until(socket, "rs")
        fake.pose.publish(pose(math.nan, 1.0, 0.0))
        fake.scan.publish(scan(np.full(100, 1.0, np.float32), beams=100,
                               angle_max=-math.radians(135) + math.radians(0.5) * 540))
        warnings: dict[str, dict[str, Any]] = {}
        while len(warnings) < 2:
            message = _until(socket, "robot_warn")
            warnings[message["kind"]] = message
        assert sorted(warnings) == ["pose", "scan"]
        assert warnings["pose"]["message"] == "pose: x is nan; last good pose kept"
        assert warnings["pose"]["ns"] == "/robot1" and warnings["pose"]["count"] == 1
        assert warnings["scan"]["message"].startswith("scan: 100 ranges where")
        fake.map.publish(map_geometry(points=(1.0, math.nan)))
        refused = _until(socket, "robot_warn", lambda m: m["kind"] == "map")
        assert "not finite" in refused["message"]
        fake.pose.publish(pose(2.0, 1.0, 0.0))
        assert _until(socket, "rs", lambda m: m["p"][0] == 2.0)["p"] == [2.0, 1.0, 0.0]
        socket.send_json({"t": "map", "on": "yes"})
        error = _until_error(socket)
        assert error["field"] == "on" and "map: on must be true or false" in error["message"]
        socket.send_json({"t": "ping", "req": 1})
        receive_until(socket, "pong")


def _until_error(socket: Any) -> dict[str, Any]:
    for _ in range(400):
        message = next_json(socket)
        if message["t"] == "error":
            return message
    raise AssertionError("no error")


def test_a_refused_map_replaces_the_one_shown_and_robots_on_one_map_share_its_key() -> None:
    with robot_bus() as (monitor, fake), local_client(monitor.app) as client, \
            client.websocket_connect("/ws") as socket:
        other = FakeMapRobot(fake.node, "/robot2")
        for each in (fake, other):
            each.map.publish(map_geometry())
        _map_on(socket)
        first = _until(socket, "map_ref")
        second = _until(socket, "map_ref", lambda m: m["ns"] != first["ns"])
        assert {first["ns"], second["ns"]} == {"/robot1", "/robot2"}
        assert first["key"] == second["key"] and len(monitor.hub.robot_hub.store) == 1
        fake.map.publish(map_geometry(points=np.zeros(7, np.float32)))
        cleared = _until(socket, "map_ref")
        assert cleared == {"t": "map_ref", "ns": "/robot1", "key": None, "url": None,
                           "source": None, "counts": None}


def test_a_page_without_the_map_gets_no_robot_state() -> None:
    with robot_bus() as (monitor, fake), local_client(monitor.app) as client, \
            client.websocket_connect("/ws") as socket, Publishing(fake, 20.0):
        socket.send_json({"t": "hello"})
        _until(socket, "robots")
        wait_until(lambda: "/robot1" in monitor.hub.robot_hub.robots, timeout=10.0)
        time.sleep(0.5)
        socket.send_json({"t": "ping", "req": 7})
        kinds = []
        while (message := next_json(socket))["t"] != "pong":
            kinds.append(message["t"])
        assert "rs" not in kinds and "map_ref" not in kinds
        _map_on(socket)
        _until(socket, "rs")
        socket.send_json({"t": "map", "on": False})
        socket.send_json({"t": "ping", "req": 8})
        receive_until(socket, "pong")
        time.sleep(0.3)
        socket.send_json({"t": "ping", "req": 9})
        while (message := next_json(socket))["t"] != "pong":
            assert message["t"] != "rs"


@pytest.mark.parametrize("extra", [ROBOT_LIMIT + 2])
def test_at_most_16_robots_are_followed(extra: int) -> None:
    with Context(BusConfig.isolated()) as context:
        monitor = Monitor(Node("monitor", "/cyborg", context=context))
        node = Node("poses", "/", context=context)
        publishers = [robot.POSE.publisher(node, f"/robot{index}") for index in range(extra)]
        try:
            with local_client(monitor.app):
                wait_until(lambda: len(monitor.hub.robot_hub.robots) == ROBOT_LIMIT,
                           timeout=10.0)
                time.sleep(1.2)
                assert len(monitor.hub.robot_hub.robots) == ROBOT_LIMIT
                assert len(monitor.hub.robots()["map_robots"]) == ROBOT_LIMIT
        finally:
            del publishers
            monitor.stop()


def test_robots_are_found_by_their_pose_and_paired_with_their_tree_by_namespace() -> None:
    assert robot.robot_namespace("/robot1/pose", robot.POSE.type_name) == "/robot1"
    assert robot.robot_namespace("/robot1/pose", "std_msgs/msg/String") is None
    assert robot.robot_namespace("/robot1/odom", robot.POSE.type_name) is None
    assert tree_runner.robot_of_runner(tree_runner.NAMESPACE) == robot.NAMESPACE
    assert tree_runner.robot_of_runner("/robot2/bt") == "/robot2"
    assert tree_runner.robot_of_runner("/bt") is None
    assert tree_runner.robot_of_runner("/robot2/trees") is None
