"""The sample trees in ../shared/trees load and run.

patrol_recharge.b3.json is run with small stand-ins for its custom nodes (MoveTo, CheckBattery,
Charge) that model a battery draining while the robot drives, to check that the engine gives the
tree its intended meaning: patrol in order, break off to recharge, then patrol again.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from cyborg.bt import (
    Action,
    Blackboard,
    Decorator,
    ManualClock,
    Status,
    check_file,
    default_registry,
    load_tree,
)
from cyborg.bt.registry import NodeRegistry
from tests.conftest import shared_dir

TREES = sorted((shared_dir() / "trees").glob("*.json"))


class MoveTo(Action):
    """Drives for `ticks_per_goal` ticks, draining 1 % per tick, then arrives."""

    def __init__(self, location: str, radius: float = 0.5) -> None:
        self.location = location

    def on_start(self) -> None:
        self.memory["left"] = self.blackboard["ticks_per_goal"]
        self.blackboard["log"].append(f"go {self.location}")

    def tick(self) -> Status:
        self.blackboard["battery"] -= 1.0
        self.memory["left"] -= 1
        if self.memory["left"] > 0:
            return Status.RUNNING
        self.blackboard["log"].append(f"at {self.location}")
        return Status.SUCCESS

    def on_halt(self) -> None:
        self.blackboard["log"].append(f"cancel {self.location}")


class CheckBattery(Decorator):
    """Latching guard: ticks its child while the battery is low or the child is RUNNING."""

    def __init__(self, threshold: float) -> None:
        self.threshold = threshold

    def tick(self) -> Status:
        if self.blackboard["battery"] < self.threshold or self.child.status is Status.RUNNING:
            return self.child.execute()
        return Status.FAILURE


class Charge(Action):
    """Charges 10 % per tick up to `target`."""

    def __init__(self, target: float = 95) -> None:
        self.target = target

    def tick(self) -> Status:
        self.blackboard["battery"] = min(100.0, self.blackboard["battery"] + 10.0)
        if self.blackboard["battery"] >= self.target:
            self.blackboard["log"].append("charged")
            return Status.SUCCESS
        return Status.RUNNING


def _robot_registry() -> NodeRegistry:
    registry = default_registry(entry_points=False)
    for cls in (MoveTo, CheckBattery, Charge):  # stand-ins for the robot's nodes
        registry.add(cls, override=True)
    return registry


@pytest.mark.parametrize("path", TREES, ids=lambda p: p.name)
def test_every_shared_tree_validates_and_runs_with_stubs(path: Path) -> None:
    problems = check_file(path, stub_missing=Status.SUCCESS)
    assert [p for p in problems if p.is_error] == []
    tree = load_tree(path, clock=ManualClock(), stub_missing=Status.SUCCESS)
    for _ in range(50):
        snapshot = tree.tick()
        tree.clock.advance(0.1)  # type: ignore[attr-defined]
        assert snapshot.visit_count > 0
    assert tree.ticks == 50


def test_shared_files_are_present() -> None:
    assert {p.name for p in TREES} >= {"patrol_recharge.b3.json", "stock_nodes.tree.json"}


def test_patrol_recharge_mission() -> None:
    blackboard = Blackboard({"battery": 40.0, "ticks_per_goal": 5, "log": []})
    tree = load_tree(shared_dir() / "trees" / "patrol_recharge.b3.json",
                     registry=_robot_registry(), clock=ManualClock(), blackboard=blackboard)
    for _ in range(120):
        tree.tick()
        tree.clock.advance(0.5)  # type: ignore[attr-defined]
    log: list[str] = blackboard["log"]
    # Patrol in file order, with 2 s waits between goals.
    assert log[:4] == ["go room1", "at room1", "go room2", "at room2"]
    # The battery falls below 25 % while driving: the recharge branch starts, and in the same
    # tick the MoveTo it replaced is halted (cancelled).
    first_dock = log.index("go Dock")
    assert log[first_dock + 1].startswith("cancel ")
    assert log[first_dock + 2:first_dock + 4] == ["at Dock", "charged"]
    cancelled = log[first_dock + 1].removeprefix("cancel ")
    assert log[first_dock - 1] == f"go {cancelled}"
    # After charging, patrol resumes where a fresh activation starts: from the first goal.
    assert log[first_dock + 4] == "go room1"
    assert cancelled in {"room1", "room2", "Outside", "room4"}
    # Every started MoveTo either arrived or was cancelled, exactly once.
    starts = [e for e in log if e.startswith("go ")]
    ends = [e for e in log if e.startswith(("at ", "cancel "))]
    assert len(ends) in (len(starts), len(starts) - 1)


def test_patrol_recharge_structure() -> None:
    tree = load_tree(shared_dir() / "trees" / "patrol_recharge.b3.json",
                     registry=_robot_registry(), clock=ManualClock())
    labels = [node.label for node in tree]
    assert labels[:4] == ["Root tree", "Priority", "CheckBattery 25", "Recharge tree"]
    assert "MoveTo room1" in labels and "Charge to 95%" in labels
    trees = [node for node in tree if node.category.value == "tree"]
    assert [(node.label, node.subtree_depth) for node in trees] == [
        ("Root tree", 0), ("Recharge tree", 0), ("Patrol tree", 0)]
