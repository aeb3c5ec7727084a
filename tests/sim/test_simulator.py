"""The simulated Pioneer LX: driving, laser, bumpers, battery, docking, navigation."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from cyborg.nav.arnl_map import parse_map, read_map
from cyborg.nav.geometry import Pose2D
from cyborg.sim.battery import Battery, ChargingState
from cyborg.sim.docking import DockState
from cyborg.sim.navigator import PathState
from cyborg.sim.simulator import Simulator
from tests.small_maps import room_map


def finished(sim: Simulator) -> bool:
    return sim.navigator.state.finished and sim.docking.state in (DockState.UNDOCKED,
                                                                   DockState.DOCKED)


def test_amroffice_every_reachable_goal_without_collision_then_dock_and_charge(
        shared: Path) -> None:
    arnl_map = read_map(shared / "maps" / "AMROffice.map")
    sim = Simulator(arnl_map, start="Dock", battery=Battery(charge_percent=60.0))
    names = [item.name for item in arnl_map.goals() if not item.is_dock]
    for name in names:
        plan = sim.go_to(name)
        assert plan.found, (name, plan.reason)
        assert sim.run_until(lambda: finished(sim), timeout=600), name
        assert sim.navigator.state is PathState.REACHED_GOAL, (name, sim.navigator.message)
        goal = arnl_map.goal(name)
        assert math.hypot(sim.pose.x - goal.x, sim.pose.y - goal.y) <= 0.2
    assert sim.base.bumps == 0 and sim.base.odometer > 80
    drained = sim.battery.charge_percent
    assert drained < 60.0
    assert sim.dock()
    assert sim.run_until(lambda: sim.docking.state is DockState.DOCKED, timeout=600)
    assert sim.battery.charging and sim.base.bumps == 0
    before = sim.battery.charge_percent
    sim.run(600)
    assert sim.battery.charge_percent > before + 5
    assert sim.battery.state is ChargingState.BULK
    sim.go_to("room1")  # undocks first: charging stops, the robot backs out, then drives
    assert sim.docking.state is DockState.UNDOCKING and not sim.battery.charging
    assert sim.run_until(lambda: sim.navigator.state is PathState.REACHED_GOAL, timeout=600)
    assert sim.docking.state is DockState.UNDOCKED


def test_goal_with_heading_is_reached_facing_it() -> None:
    sim = Simulator(parse_map(room_map(['GoalWithHeading 8000 3000 -90 "" ICON "east"'])),
                    start=Pose2D(2.0, 3.0))
    assert sim.go_to("east").found
    assert sim.run_until(lambda: sim.navigator.state.finished, timeout=120)
    assert sim.navigator.state is PathState.REACHED_GOAL
    assert abs(sim.pose.theta - math.radians(-90)) <= math.radians(4)


def test_unreachable_goal_fails_to_plan_and_the_robot_stays() -> None:
    sim = Simulator(parse_map(room_map(['ForbiddenLine 0 0 0 "" ICON "" 5000 2400 5000 3600'])),
                    start=Pose2D(2.0, 3.0))
    result = sim.go_to(Pose2D(8.0, 3.0))
    assert not result.found and sim.navigator.state is PathState.FAILED_PLAN
    sim.run(5)
    assert sim.pose.distance_to(Pose2D(2.0, 3.0)) < 1e-9


def test_laser_sees_the_room() -> None:
    sim = Simulator(parse_map(room_map([])), start=Pose2D(2.0, 1.0, 0.0))
    spec = sim.laser.spec
    assert len(sim.ranges) == 541
    ahead = sim.ranges[270]  # straight ahead: the wall at x = 5 m, from the scanner at 2.267 m
    assert ahead == pytest.approx(5.0 - 2.0 - spec.mount_x, abs=0.06)
    left = sim.ranges[270 + 180]  # 90 degrees left: the wall at y = 6 m
    assert left == pytest.approx(5.0, abs=0.06)
    assert np.all(sim.ranges <= spec.range_max + 1.0)


def test_bumper_reports_contact_and_the_body_stays_out_of_walls() -> None:
    sim = Simulator(parse_map(room_map([])), start=Pose2D(4.0, 1.0, 0.0))
    for _ in range(200):
        sim.base.command(0.3, 0.0, 0.02)
    assert sim.base.bumpers.front and sim.base.bumps == 1
    assert sim.base.body_clearance(sim.pose) >= 0.0
    front = sim.pose.x + sim.base.footprint.length / 2
    assert 5.0 - 0.1 < front <= 5.0 + sim.world.resolution  # stopped at the wall, within a cell
    for _ in range(50):
        sim.base.command(-0.3, 0.0, 0.02)  # backing off is allowed and clears the bumper
    assert not sim.base.bumpers.any


def test_box_unknown_to_the_planner_is_driven_around() -> None:
    box = 'Sim.BoxObstacle 0 0 0 "" ICON "" 3000 2200 3600 3800'  # across the straight line
    sim = Simulator(parse_map(room_map([box])), start=Pose2D(1.0, 3.0, 0.0))
    plan = sim.go_to(Pose2D(4.5, 3.0))
    assert plan.found and plan.length < 3.6  # the planner does not know the box
    assert sim.run_until(lambda: sim.navigator.state.finished, timeout=300)
    assert sim.navigator.state is PathState.REACHED_GOAL
    assert sim.navigator.replans >= 1 and sim.base.bumps == 0


def test_no_progress_aborts_and_cancel_stops() -> None:
    # a box closes the door: the robot replans, finds no way, and gives up after the timeout
    box = 'Sim.BoxObstacle 0 0 0 "" ICON "" 4700 2300 5300 3700'
    sim = Simulator(parse_map(room_map([box])), start=Pose2D(2.0, 3.0, 0.0))
    assert sim.go_to(Pose2D(8.0, 3.0)).found
    assert sim.run_until(lambda: sim.navigator.state.finished, timeout=120)
    assert sim.navigator.state is PathState.FAILED_MOVE
    assert "no progress" in sim.navigator.message and sim.base.bumps == 0
    sim.go_to(Pose2D(1.0, 5.0))
    sim.run(1.0)
    sim.cancel()
    assert sim.navigator.state.value == "ABORTED_PATHPLAN"
    sim.run(3.0)
    assert sim.base.speed == 0.0 and sim.base.turn_rate == 0.0


def test_battery_lasts_thirteen_hours_idle_and_charges_in_stages() -> None:
    battery = Battery()
    for _ in range(13 * 60):
        battery.step(60.0, 0.0)
    assert battery.charge_percent == pytest.approx(0.0, abs=0.5) and battery.empty
    assert battery.voltage == pytest.approx(battery.empty_volts, abs=0.05)
    moving = Battery()
    moving.step(3600.0, 1.0)
    assert moving.charge_percent < 100 - 100 / 13
    battery.charging = True
    states = set()
    for _ in range(6 * 60):
        battery.step(60.0, 0.0)
        states.add(battery.state)
    assert {ChargingState.BULK, ChargingState.OVERCHARGE, ChargingState.FLOAT} <= states
    assert battery.charge_percent == 100.0


def test_dock_needs_a_dock() -> None:
    sim = Simulator(parse_map(room_map([])), start=Pose2D(2.0, 3.0))
    assert not sim.dock() and "has no Dock" in sim.docking.message


def test_loop_paces_simulated_time_by_the_speed_factor() -> None:
    import time

    from cyborg.sim.loop import SimulationLoop
    sim = Simulator(parse_map(room_map([])), start=Pose2D(2.0, 3.0))
    with pytest.raises(ValueError, match="speed must be positive"):
        SimulationLoop(sim, speed=-1)
    loop = SimulationLoop(sim, speed=10.0)
    loop.start()
    time.sleep(1.0)
    loop.stop()
    assert 7.0 <= sim.time <= 11.0  # ten simulated seconds per wall second
    flat_out = SimulationLoop(sim, speed=0)
    begin = sim.time
    flat_out.start()
    time.sleep(0.5)
    flat_out.stop()
    assert sim.time - begin > 20.0 and flat_out.error is None
