"""ReadBattery: the battery reading in the global blackboard, as mode conditions read it."""

from __future__ import annotations

import pytest

from cyborg.bt import SUCCESS, ManualClock, TreeLoadError
from cyborg.modes.conditions import Condition
from cyborg.robot.protocol import DockState
from tests.builders import N
from tests.robot.fake_robot import FakeRobot, robot_tree


def test_read_battery_writes_the_reading_each_tick_and_nothing_before_the_first() -> None:
    robot = FakeRobot(battery=None)
    tree = robot_tree(N("Sequence", N("ReadBattery"), N("Succeeder")), robot, ManualClock())
    assert tree.tick().status is SUCCESS
    assert "battery" not in tree.blackboard.globals
    robot.set_battery(42.5)
    tree.tick()
    assert tree.blackboard.globals["battery"] == {
        "percent": 42.5, "charging": False, "docked": False, "dock_state": "undocked",
        "time": 0.0}
    assert tree.blackboard.globals["battery_percent"] == 42.5
    robot.set_battery(43.0, DockState.DOCKED)
    tree.tick()
    entry = tree.blackboard.globals["battery"]
    assert (entry["percent"], entry["docked"], entry["charging"]) == (43.0, True, True)


def test_a_mode_condition_reads_what_read_battery_wrote() -> None:
    robot = FakeRobot()
    tree = robot_tree(N("ReadBattery", key="power"), robot, ManualClock())
    low = Condition("power.percent < 30")
    robot.set_battery(31.0)
    tree.tick()
    assert not low.holds(tree.blackboard.globals)
    robot.set_battery(29.0)
    tree.tick()
    assert low.holds(tree.blackboard.globals)


def test_an_empty_key_is_a_load_error() -> None:
    with pytest.raises(TreeLoadError, match="key"):
        robot_tree(N("ReadBattery", key=""), FakeRobot())
