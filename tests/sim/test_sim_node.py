"""The simulated robot's ARNL-like interface and the navigation services, on the bus."""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from cyborg.bus import BusConfig, Context, GoalStatus, Node, new_message
from cyborg.bus.clock import SimClock
from cyborg.nav.arnl_map import read_map
from cyborg.sim.loop import SimulationLoop
from cyborg.sim.node import CANCELED, FEEDBACK_PERIOD, NO_PATH, SUCCEEDED, SimulatorNode
from cyborg.sim.simulator import Simulator


@pytest.fixture
def robot(shared: Path) -> Iterator[tuple[Node, Simulator, SimulationLoop]]:
    with Context(BusConfig.isolated()) as context:
        sim = Simulator(read_map(shared / "maps" / "AMROffice.map"), start="Dock")
        loop = SimulationLoop(sim, speed=20)
        SimulatorNode(Node("arnl", "/cyborg", context=context), loop)
        loop.start()
        yield Node("client", "/cyborg", context=context), sim, loop
        loop.stop()


def call(node: Node, name: str, service: str, **fields: Any) -> Any:
    client = node.create_client(name, service)
    return client.call(new_message(node.types, f"{service}_Request", fields), timeout=10)


def test_goals_distances_and_closest_goal(robot: tuple[Node, Simulator, SimulationLoop]) -> None:
    node, sim, _loop = robot
    goals = call(node, "nav/get_available_goals", "cyborg_msgs/srv/AvailableGoals").goals
    assert [goal.name for goal in goals] == ["Dock", "Outside", "room4", "Far Away", "room2",
                                             "room1"]
    assert goals[0].position.theta == pytest.approx(math.radians(-91.9))  # radians, not degrees
    room1 = sim.map.goal("room1")
    pose = {"position": {"x": room1.x, "y": room1.y}, "orientation": {"w": 1.0}}
    distance = call(node, "nav/get_distance_to_goal", "cyborg_msgs/srv/DistanceToGoal",
                    goal=pose).distance
    assert 8.0 < distance < 10.0
    wall_x, wall_y = (float(value) for value in sim.map.points[len(sim.map.points) // 2])
    inside_wall = {"position": {"x": wall_x, "y": wall_y}, "orientation": {"w": 1.0}}
    assert call(node, "nav/get_distance_to_goal", "cyborg_msgs/srv/DistanceToGoal",
                goal=inside_wall).distance == math.inf
    closest = call(node, "nav/get_closest_goal", "cyborg_msgs/srv/ClosestGoal")
    assert (closest.name, closest.distance) == ("Dock", 0.0)
    plan = call(node, "make_plan", "cyborg_msgs/srv/MakePlan",
                goal={"x": room1.x, "y": room1.y})
    assert plan.found and plan.length == pytest.approx(distance, abs=1e-6)
    assert len(plan.path.poses) >= 2
    none = call(node, "make_plan", "cyborg_msgs/srv/MakePlan", goal={"x": wall_x, "y": wall_y})
    assert not none.found and "GOAL_OCCUPIED" in none.message and none.length == math.inf


def test_load_map_file_switches_maps_and_rejects_bad_files(
        robot: tuple[Node, Simulator, SimulationLoop], shared: Path, tmp_path: Path) -> None:
    node, sim, _loop = robot
    bad = tmp_path / "bad.map"
    bad.write_text("2D-Map\nCairn: Goal 1 2\n")
    reply = call(node, "load_map_file", "cyborg_msgs/srv/LoadMapFile", path=str(bad))
    assert not reply.success and f"{bad}:2:" in reply.message
    assert sim.map.source.endswith("AMROffice.map")  # the old map stays
    reply = call(node, "load_map_file", "cyborg_msgs/srv/LoadMapFile",
                 path=str(shared / "maps" / "columbia.map"))
    assert reply.success and "10 goals" in reply.message
    assert sim.map.source.endswith("columbia.map")
    goals = call(node, "nav/get_available_goals", "cyborg_msgs/srv/AvailableGoals").goals
    assert "Impossible Goal" in [goal.name for goal in goals]


def test_move_to_goal_feedback_cancel_and_failure(
        robot: tuple[Node, Simulator, SimulationLoop]) -> None:
    node, sim, loop = robot
    action = node.create_action_client("move_to_goal", "cyborg_msgs/action/MoveToGoal")
    goal_type = "cyborg_msgs/action/MoveToGoal_Goal"
    feedback: list[Any] = []
    goal = action.send_goal(new_message(node.types, goal_type, {"goal_name": "room1"}),
                            feedback=feedback.append)
    status, result = goal.result(timeout=60)
    assert (status, result.outcome) == (GoalStatus.SUCCEEDED, SUCCEEDED)
    assert feedback and feedback[0].distance_remaining > feedback[-1].distance_remaining
    # feedback follows simulated time: one per FEEDBACK_PERIOD, whatever the speed
    driven = feedback[0].distance_remaining
    assert len(feedback) >= driven / 2.0 / FEEDBACK_PERIOD  # at most 2 m/s
    assert sim.pose.distance_to(sim.map.goal("room1")) < 0.2  # type: ignore[arg-type]
    loop.speed = 2.0  # slow enough to cancel on the way
    moving = threading.Event()
    goal = action.send_goal(new_message(node.types, goal_type, {"goal_name": "Far Away"}),
                            feedback=lambda _f: moving.set())
    assert moving.wait(10)
    goal.cancel()
    status, result = goal.result(timeout=10)
    assert (status, result.outcome) == (GoalStatus.CANCELED, CANCELED)
    with loop.lock:
        assert sim.navigator.state.value == "ABORTED_PATHPLAN"
    unknown = action.send_goal(new_message(node.types, goal_type, {"goal_name": "kitchen"}))
    status, result = unknown.result(timeout=10)
    assert (status, result.outcome) == (GoalStatus.ABORTED, NO_PATH)
    assert "no goal named 'kitchen'" in result.message


def test_topics_battery_and_docking(robot: tuple[Node, Simulator, SimulationLoop]) -> None:
    node, _sim, _loop = robot
    got: dict[str, threading.Event] = {name: threading.Event() for name in (
        "clock", "pose", "odom", "scan", "battery", "state")}
    batteries: list[Any] = []
    node.create_subscription("/clock", "rosgraph_msgs/msg/Clock", lambda _m: got["clock"].set())
    node.create_subscription("pose", "geometry_msgs/msg/Pose2D", lambda _m: got["pose"].set())

    def odometry(message: Any) -> None:
        at_dock = (message.pose.pose.position.x, message.pose.pose.position.y) == pytest.approx(
            (-2.822, -2.937), abs=0.5)
        if message.header.frame_id == "map" and at_dock and len(message.pose.covariance) == 36:
            got["odom"].set()
    node.create_subscription("odom", "nav_msgs/msg/Odometry", odometry)

    def scan(message: Any) -> None:
        if len(message.ranges) == 541:
            got["scan"].set()
    node.create_subscription("scan", "sensor_msgs/msg/LaserScan", scan)
    node.create_subscription("arnl_path_state", "std_msgs/msg/String",
                             lambda _m: got["state"].set())

    def battery(message: Any) -> None:
        batteries.append(message)
        got["battery"].set()
    node.create_subscription("battery_status", "cyborg_msgs/msg/BatteryStatus", battery)
    for name, event in got.items():
        assert event.wait(10), name
    assert batteries[-1].dock_state == "UNDOCKED" and not batteries[-1].charging
    assert call(node, "dock", "std_srvs/srv/Trigger").success
    assert call(node, "undock", "std_srvs/srv/Trigger").success is False  # still docking
    for _ in range(200):
        if batteries[-1].dock_state == "DOCKED":
            break
        threading.Event().wait(0.05)
    last = batteries[-1]
    assert last.dock_state == "DOCKED" and last.charging
    assert last.charging_state in (1, 2, 3)  # bulk, overcharge or float


def test_sim_clock_follows_the_simulation(robot: tuple[Node, Simulator, SimulationLoop]) -> None:
    node, sim, _loop = robot
    clock = SimClock(node)
    assert clock.wait_for_time(10) and clock.started
    start = clock.now()
    assert start > 0
    stop = threading.Event()
    clock.sleep_until(start + 2.0, stop)  # 2 simulated seconds: 0.1 s of wall time at 20x
    assert clock.now() >= start + 2.0
    assert abs(clock.now() - sim.time) < 1.0
    stop.set()
    clock.sleep_until(clock.now() + 1e6, stop)  # returns at once when woken
    clock.destroy()


def test_closing_the_bus_under_a_running_simulation_ends_it_quietly(
        shared: Path, caplog: pytest.LogCaptureFixture) -> None:
    """A context closed while the loop still steps (an interrupted stop, an exception path):
    the loop ends, and no "the simulation stopped" error is reported."""
    sim = Simulator(read_map(shared / "maps" / "AMROffice.map"), start="Dock")
    loop = SimulationLoop(sim, speed=0)
    with Context(BusConfig.isolated()) as context:
        SimulatorNode(Node("arnl", "/cyborg", context=context), loop)
        loop.start()
        deadline = time.monotonic() + 5
        while sim.time < 1.0 and time.monotonic() < deadline:
            time.sleep(0.01)
    deadline = time.monotonic() + 5
    while loop.running and time.monotonic() < deadline:
        time.sleep(0.01)
    assert not loop.running and loop.error is None
    assert not [r for r in caplog.records if "simulation stopped" in r.getMessage()]
