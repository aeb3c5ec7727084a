"""Stand-ins for the robot commands' tests without a bus: a robot the hub follows, its bus
clients recording every call, goals that end when the test says, and pages whose queues the
test reads."""

from __future__ import annotations

import asyncio
import json
import time
from collections.abc import Callable
from types import SimpleNamespace
from typing import Any, cast

from cyborg.interfaces.robot import MoveOutcome
from cyborg.monitor.client import Client
from cyborg.monitor.hub import Hub
from cyborg.monitor.map_store import StoredMap
from cyborg.monitor.robot_clients import MoveGoal, RobotClients, clamp_drive
from cyborg.monitor.robot_hub import DETECTIONS_INTERVAL, OBJECTS_INTERVAL, PATH_INTERVAL
from cyborg.monitor.robot_outbox import RobotOutbox, Throttle
from cyborg.monitor.robot_source import RobotSource
from tests.monitor.monitor_protocol import bare_hub

ROBOT = "/cyborg"
HOME = {"kind": "RobotHome", "category": 4, "name": "Home", "description": "",
        "pose": [2.0, 3.0, 1.5708], "outline": []}


class FakeGoal:
    """A goal the fake robot accepted; :meth:`end` ends it as the robot would."""

    def __init__(self, fields: dict[str, Any]) -> None:
        self.fields = fields
        self.cancelled = False
        self._callbacks: list[Callable[[object], object]] = []
        self._result: tuple[int, Any] | None = None
        self.client = SimpleNamespace(node=SimpleNamespace(context=SimpleNamespace(
            calls=SimpleNamespace(submit=lambda function, *args: function(*args)))))

    def end(self, outcome: MoveOutcome, message: str) -> None:
        self._result = (4, SimpleNamespace(outcome=int(outcome), message=message))
        for callback in self._callbacks:
            callback(self)

    @property
    def done(self) -> bool:
        return self._result is not None

    def add_done_callback(self, callback: Callable[[object], object]) -> None:
        self._callbacks.append(callback)
        if self._result is not None:
            callback(self)

    def result(self, _timeout: float | None = None) -> tuple[int, Any]:
        assert self._result is not None
        return self._result

    def cancel(self, _timeout: float = 5.0) -> bool:
        self.cancelled = True
        return True


class FakeBus:
    """What :class:`RobotClients` offers, recorded; ``refuse`` maps a service to its refusal."""

    def __init__(self, namespace: str) -> None:
        self.namespace = namespace
        self.calls: list[tuple[Any, ...]] = []
        self.goals: list[FakeGoal] = []
        self.refuse: dict[str, str] = {}
        self.names = ["Office", "Library"]

    def trigger(self, service: str) -> tuple[bool, str]:
        self.calls.append((service,))
        if service in self.refuse:
            return False, self.refuse[service]
        return True, {"stop": "stopped", "dock": "docking", "undock": "undocking"}[service]

    def set_pose(self, x: float, y: float, theta: float) -> tuple[bool, str]:
        self.calls.append(("set_pose", x, y, theta))
        if "set_pose" in self.refuse:
            return False, self.refuse["set_pose"]
        return True, f"at ({x:.2f}, {y:.2f})"

    def goal_names(self) -> list[str]:
        self.calls.append(("goal_names",))
        return list(self.names)

    def send_goal(self, *, name: str = "", pose: tuple[float, float, float] | None = None,
                  use_heading: bool = False) -> MoveGoal:
        goal = FakeGoal({"name": name, "pose": pose, "use_heading": use_heading})
        self.calls.append(("goal", name, pose, use_heading))
        self.goals.append(goal)
        return cast(MoveGoal, goal)

    def drive(self, vx: float, wz: float) -> tuple[float, float]:
        sent = clamp_drive(vx, wz)
        self.calls.append(("drive", *sent))
        return sent

    def destroy(self) -> None:
        self.calls.append(("destroy",))


class FakeRobotSource:
    """The robot as the hub follows it: on the bus, at a pose."""

    def __init__(self, namespace: str) -> None:
        self.namespace, self.alive, self.pose = namespace, True, [1.0, 2.0, 0.5]


def acting_hub(*, token: str | None = None, objects: tuple[dict[str, Any], ...] = (HOME,),
               robots: tuple[str, ...] = (ROBOT,)) -> tuple[Hub, dict[str, FakeBus]]:
    """A hub over fake trees (``<robot>/bt``, as ``cyborg up`` places them) with ``robots``
    (default /cyborg) on a map of ``objects``; its robot commands go to fake bus clients, one
    per robot, returned by namespace."""
    trees = tuple(f"{robot}/bt" for robot in robots)
    hub = bare_hub(token=token, namespaces=trees, runners=trees)
    stored = StoredMap("0" * 32, b"", 0, "campus.map", {"lines": 0, "points": 0,
                                                        "objects": len(objects)}, objects)
    for robot in robots:
        source = cast(RobotSource, FakeRobotSource(robot))
        hub.robot_hub.robots[robot] = RobotOutbox(source, Throttle(PATH_INTERVAL),
                                                  Throttle(DETECTIONS_INTERVAL),
                                                  Throttle(OBJECTS_INTERVAL), map=stored)
    buses: dict[str, FakeBus] = {}

    def make(namespace: str) -> RobotClients:
        buses[namespace] = FakeBus(namespace)
        return cast(RobotClients, buses[namespace])

    hub.robot_commands.use(make)
    return hub, buses


def page(hub: Hub, number: int, *, may_control: bool = True) -> Client:
    """A page connected to ``hub`` (no socket: the test reads its queue)."""
    client = Client(number, cast(Any, None), may_control=may_control)
    hub.clients.add(client)
    return client


_KEPT: dict[int, list[dict[str, Any]]] = {}
"""Messages queued to each page (by ``id``) and not yet taken by a test."""


def of_kind(client: Client, *kinds: str) -> list[dict[str, Any]]:
    """The messages of the types ``kinds`` queued to ``client`` so far; they are taken, the
    others kept for later."""
    kept = _KEPT.setdefault(id(client), [])
    while not client.queue.empty():
        kept.append(json.loads(client.queue.get_nowait()))
    client.queued_bytes = 0
    taken = [message for message in kept if message["t"] in kinds]
    kept[:] = [message for message in kept if message["t"] not in kinds]
    return taken


async def idle() -> None:
    """Lets the event loop run what is ready (tasks following goals, tours)."""
    for _ in range(20):
        await asyncio.sleep(0)


async def until(predicate: Callable[[], object], what: str, timeout: float = 10.0) -> None:
    """Lets the event loop run until ``predicate()`` holds (worker threads included)."""
    deadline = time.monotonic() + timeout
    while not predicate():
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out after {timeout:g} s waiting for {what}")
        await asyncio.sleep(0.005)
