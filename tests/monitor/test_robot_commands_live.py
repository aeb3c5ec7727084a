"""The robot commands against the simulated robot (campus map, patrol tree, monitor on one
isolated bus): the monitor's bus clients reach the simulator's action and services, a goal
pauses the patrol and the robot gets there, the robot's own refusals come back as the answer,
a stop ends a goal, and driving by hand moves the robot."""

from __future__ import annotations

import math
import time
from collections.abc import Iterator
from typing import Any

import pytest

from cyborg.interfaces.robot import TELEOP_MAX_SPEED
from cyborg.monitor import Monitor
from tests.monitor.monitor_protocol import (
    campus_system,
    local_client,
    monitor_for,
    next_json,
    receive_until,
)
from tests.running_system import System, wait_until

pytestmark = pytest.mark.heavy

ROBOT = "/cyborg"
OFFICE = (11.0, 3.0)
"""The campus map's goal "Office" (map file: Cairn Goal 11000 3000)."""


@pytest.fixture
def live() -> Iterator[tuple[System, Monitor]]:
    with campus_system() as system:
        monitor = monitor_for(system)
        try:
            yield system, monitor
        finally:
            monitor.stop()


ENDED: list[dict[str, Any]] = []
"""``robot_result`` messages that came while a test waited for an answer (a goal a stop ended
may end before the stop is answered: the stop waits for the tree's stop too)."""


def _answer(socket: Any, command: dict[str, Any]) -> dict[str, Any]:
    socket.send_json(command)
    while True:
        message = next_json(socket)
        if message["t"] == "robot_result":
            ENDED.append(message)
        elif message["t"] == "result" and message["req"] == command.get("req"):
            return message


def _ended(socket: Any, goal: str, timeout: float = 90.0) -> dict[str, Any]:
    """The ``robot_result`` of ``goal``, waiting up to ``timeout`` s for each message."""
    for message in list(ENDED):
        if message["goal"] == goal:
            ENDED.remove(message)
            return message
    for _ in range(1000):
        message = next_json(socket, timeout)
        if message["t"] == "robot_result" and message["goal"] == goal:
            return message
    raise AssertionError(f"no robot_result for {goal}")


def _controlling(socket: Any, monitor: Monitor) -> None:
    socket.send_json({"t": "hello"})
    receive_until(socket, "seat")
    assert _answer(socket, {"t": "claim", "req": 1})["ok"] is True
    wait_until(lambda: ROBOT in monitor.hub.robot_hub.robots, 20, "the monitor to find the robot")


def test_a_goal_pauses_the_patrol_and_the_robot_gets_there(live: tuple[System, Monitor]
                                                           ) -> None:
    system, monitor = live
    with local_client(monitor.app) as client, client.websocket_connect("/ws") as socket:
        _controlling(socket, monitor)
        wait_until(lambda: system.runner.enabled, 10, "the patrol to run")
        unknown = _answer(socket, {"t": "go", "ns": ROBOT, "goal": "Atlantis", "req": 2})
        assert unknown["ok"] is False and unknown["field"] == "goal"
        assert "no goal 'Atlantis' on the map of /cyborg (goals: " in unknown["message"]
        assert "'Office'" in unknown["message"], "the robot's own list of goals"
        assert system.runner.enabled, "a refused goal leaves the tree running"
        off = _answer(socket, {"t": "set_pose", "ns": ROBOT, "pose": [500.0, 500.0, 0.0],
                               "req": 3})
        assert off["ok"] is False and off["field"] == "pose"
        assert "/cyborg/set_pose refused: " in off["message"]
        assert "off the map" in off["message"], off["message"]
        went = _answer(socket, {"t": "go", "ns": ROBOT, "goal": "Office", "req": 4})
        assert went["ok"] is True and went["paused"] == "/cyborg/bt", went
        assert not system.runner.enabled, "the patrol is paused for the manual goal"
        ended = _ended(socket, "'Office'")
        assert ended["outcome"] == "reached" and ended["req"] == 4, ended
        pose = system.sim.pose
        assert math.hypot(pose.x - OFFICE[0], pose.y - OFFICE[1]) < 0.5, pose
        assert not system.runner.enabled, "the tree stays paused until someone resumes it"


def test_set_pose_stop_and_driving_by_hand(live: tuple[System, Monitor]) -> None:
    system, monitor = live
    with local_client(monitor.app) as client, client.websocket_connect("/ws") as socket:
        _controlling(socket, monitor)
        placed = _answer(socket, {"t": "set_pose", "ns": ROBOT, "pose": [11.0, 3.0, 1.0],
                                  "req": 2})
        assert placed["ok"] is True, placed
        pose = system.sim.pose
        assert (pose.x, pose.y) == pytest.approx(OFFICE, abs=0.01)
        far = _answer(socket, {"t": "go_pose", "ns": ROBOT, "pose": [40.0, 6.0], "req": 3})
        assert far["ok"] is True
        wait_until(lambda: math.hypot(system.sim.pose.x - OFFICE[0],
                                      system.sim.pose.y - OFFICE[1]) > 0.3, 60, "the robot to move")
        stopped = _answer(socket, {"t": "stop", "ns": ROBOT, "req": 4})
        assert stopped["ok"] is True and stopped["paused"] is None
        assert stopped["stopped"] == ["/cyborg/bt"] and system.runner.stopped, stopped
        ended = _ended(socket, "(40.00, 6.00)")
        assert ended["outcome"] == "failed" and "stop" in ended["message"], ended
        wait_until(lambda: system.sim.base.speed == 0, 20, "the robot to brake")
        start = system.sim.pose
        sent_at = [0.0]

        def driven() -> bool:  # 10 Hz, as the page: the robot's deadman wants a command at least
            if time.monotonic() - sent_at[0] >= 0.1:  # every 0.5 s
                sent_at[0] = time.monotonic()
                socket.send_json({"t": "drive", "ns": ROBOT, "vx": 3.0, "wz": 0.0})
            return math.hypot(system.sim.pose.x - start.x, system.sim.pose.y - start.y) > 0.1

        wait_until(driven, 30, "the robot to drive by hand")
        assert 0 < system.sim.base.speed <= TELEOP_MAX_SPEED + 1e-9, "clamped"
