"""A scripted robot for behaviour-node tests: no bus, no simulator, fully controlled."""

from __future__ import annotations

import json
import math
from concurrent.futures import Future
from dataclasses import dataclass, field

from cyborg.bt import Blackboard, ManualClock, Tree, loads_tree
from cyborg.nav.geometry import Pose2D
from cyborg.robot.perceiving import SeenObject
from cyborg.robot.protocol import ROBOT, BatteryReading, DockState, Goal, MoveOutcome, RobotError
from tests.builders import N, registry, tree_json


@dataclass
class FakeMove:
    goal: str
    outcome: MoveOutcome | None = None
    message: str = ""
    remaining: float = math.inf
    cancelled: bool = False
    waiting: bool = False

    @property
    def done(self) -> bool:
        return self.outcome is not None

    def cancel(self) -> None:
        if not self.done:
            self.cancelled = True
            self.outcome = MoveOutcome.CANCELED

    def finish(self, outcome: MoveOutcome, message: str = "") -> None:
        self.outcome, self.message = outcome, message


@dataclass
class FakeRobot:
    goals_: dict[str, Goal] = field(default_factory=lambda: {
        "home": Goal("home", Pose2D(0.0, 0.0)),
        "kitchen": Goal("kitchen", Pose2D(10.0, 0.0, math.pi / 2), has_heading=True),
        "Dock": Goal("Dock", Pose2D(-2.0, 0.0, math.pi), has_heading=True)})
    pose: Pose2D | None = field(default_factory=lambda: Pose2D(5.0, 5.0))
    battery: BatteryReading | None = field(
        default_factory=lambda: BatteryReading(80.0, False, DockState.UNDOCKED))
    moves: list[FakeMove] = field(default_factory=list)
    dock_requests: int = 0
    undock_requests: int = 0
    stops: int = 0
    can_dock: bool = True
    no_path_to: set[str] = field(default_factory=set)
    distances: dict[str, float] = field(default_factory=dict)
    reachable: bool = True
    """False: the robot's services and action server are gone (the simulator was killed)."""
    send_attempts: int = 0
    """Calls of move_to, sent or not."""
    help_calls: list[tuple[str, float]] = field(default_factory=list)
    """Each call_for_help: ``(reason, time)``."""
    seen: list[SeenObject] = field(default_factory=list)
    """What the tracker follows (objects())."""
    said: list[str] = field(default_factory=list)
    drives: list[tuple[float, float]] = field(default_factory=list)
    """Every speed command, (m/s, rad/s)."""

    def goals(self, refresh: bool = False) -> dict[str, Goal]:
        if refresh and not self.reachable:
            raise RobotError("service /cyborg/nav/get_available_goals is not available")
        return dict(self.goals_)

    def move_to(self, goal: str) -> FakeMove:
        self.send_attempts += 1
        if goal == "offline" or not self.reachable:
            raise RobotError(f"cannot send the robot to {goal!r}: action /cyborg/move_to_goal: "
                             "service /cyborg/move_to_goal/_action/send_goal is not available")
        move = FakeMove(goal)
        if goal in self.no_path_to:
            move.finish(MoveOutcome.NO_PATH, "NO_VALID_PATH: cut off")
        self.moves.append(move)
        return move

    def dock(self) -> tuple[bool, str]:
        self.dock_requests += 1
        return (True, "docking") if self.can_dock else (False, "the map has no Dock")

    def call_for_help(self, reason: str, time: float) -> None:
        self.help_calls.append((reason, time))

    def undock(self) -> tuple[bool, str]:
        self.undock_requests += 1
        return True, "undocking"

    def stop(self) -> None:
        self.stops += 1

    def objects(self) -> list[SeenObject]:
        return list(self.seen)

    def say(self, text: str) -> None:
        self.said.append(text)

    def drive(self, linear: float, angular: float) -> None:
        self.drives.append((linear, angular))

    def set_battery(self, percent: float, state: DockState = DockState.UNDOCKED) -> None:
        self.battery = BatteryReading(percent, state is DockState.DOCKED, state)

    def distance_to(self, goal: Pose2D) -> Future[float]:
        future: Future[float] = Future()
        name = next(name for name, item in self.goals_.items() if item.pose == goal)
        future.set_result(self.distances.get(name, math.inf))
        return future

    def closest_goal(self) -> Future[tuple[str, float]]:
        future: Future[tuple[str, float]] = Future()
        reachable = {name: d for name, d in self.distances.items() if math.isfinite(d)}
        if reachable:
            name = min(reachable, key=reachable.__getitem__)
            future.set_result((name, reachable[name]))
        else:
            future.set_result(("", math.inf))
        return future


def robot_tree(spec: N, robot: FakeRobot, clock: ManualClock | None = None) -> Tree:
    """A tree of ``spec`` acting on ``robot``, on a manual clock."""
    reg = registry()
    text = json.dumps(tree_json(spec, reg=reg))
    return loads_tree(text, registry=reg, clock=clock or ManualClock(),
                      blackboard=Blackboard({"events": []}, resources={ROBOT: robot}))
