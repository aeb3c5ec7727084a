"""End to end in simulated time: a person standing in a corridor, as the tracker reports them,
makes the simulated robot drive around them, or wait for them where there is no room, and a
tree's ``MoveTo`` still arrives once they are gone.

A stand-in tracker publishes the person on the robot's ``objects`` (the contract's
``TrackedObjects`` in the map frame, stamped on ``/clock``) while they stand there, and nothing
once they left; the simulator's node follows that topic and the navigator plans around them.
The tree is ``Sequence[MoveTo end, Say arrived]`` on the robot through the bus.
"""

from __future__ import annotations

import math
import time
from pathlib import Path
from typing import Any

import pytest

from cyborg.bus import Node, SimClock
from cyborg.bus.msgs.builtin_interfaces.msg import Time
from cyborg.bus.msgs.cyborg_msgs.msg import TrackedObject, TrackedObjects
from cyborg.bus.msgs.geometry_msgs.msg import Point, Vector3
from cyborg.bus.msgs.std_msgs.msg import Header
from cyborg.interfaces import perception, robot
from cyborg.interfaces.robot import PathState
from tests.running_system import System, running_system, write_tree
from tests.small_maps import corridor_map, write

PERSON_X = 7.0
"""Where along the corridor the person stands (m); they stand in its middle."""
TREE = {"name": "Sequence", "composite": True, "children": [
    {"name": "MoveTo", "props": {"location": "end"}},
    {"name": "Say", "props": {"text": "arrived"}}]}


class StandInTracker:
    """Publishes one person standing at ``(x, y)`` on the robot's ``objects`` while present."""

    def __init__(self, node: Node, x: float, y: float) -> None:
        self.clock = SimClock(node)
        self.x, self.y = x, y
        self.present = True
        self._publisher = perception.OBJECTS.publisher(node, robot.NAMESPACE)

    def publish(self) -> None:
        now = self.clock.now()
        stamp = Time(sec=int(now), nanosec=int(now % 1 * 1e9))
        seen = [TrackedObject(id=1, label="person", confidence=0.9,
                              position=Point(x=self.x, y=self.y, z=0.0),
                              velocity=Vector3(x=0.0, y=0.0, z=0.0), last_seen=stamp,
                              times_seen=20, distance=0.0, bearing=0.0)] if self.present else []
        self._publisher.publish(TrackedObjects(header=Header(stamp=stamp, frame_id="map"),
                                               objects=seen))


def corridor(folder: Path, width: float) -> Path:
    middle = round(width * 500)
    return write(folder, "corridor.map", corridor_map(width, cairns=[
        f'Goal 1000 {middle} 0 "" ICON "start"', f'Goal 13000 {middle} 0 "" ICON "end"']))


def drive_past(system: System, tracker: StandInTracker, leave_after_waiting: float,
               timeout: float) -> tuple[list[str], list[Any], float]:
    """Publish the person every 10 wall ms until the tree says it arrived.

    The person leaves ``leave_after_waiting`` simulated seconds after the robot starts waiting
    for them (never, if it never waits). Returns the path states heard, what the robot said,
    and the closest the robot's centre came to the person while they stood there.
    """
    states: list[str] = []
    said: list[Any] = []
    robot.PATH_STATE.subscription(system.client, lambda state: states.append(state.data),
                                  robot.NAMESPACE)
    perception.SAY.subscription(system.client, said.append, robot.NAMESPACE)
    waiting_since: float | None = None
    closest = math.inf
    deadline = time.monotonic() + timeout
    while not said:
        assert time.monotonic() < deadline, f"no arrival; path states {states}"
        sim = system.sim
        if waiting_since is None and sim.navigator.waiting:
            waiting_since = sim.time
        if waiting_since is not None and sim.time - waiting_since >= leave_after_waiting:
            tracker.present = False
        if tracker.present:
            closest = min(closest, math.hypot(sim.pose.x - tracker.x, sim.pose.y - tracker.y))
        tracker.publish()
        time.sleep(0.01)
    return states, said, closest


def arrived_at_the_end(system: System) -> bool:
    pose, end = system.sim.pose, system.sim.map.goal("end")
    return math.hypot(pose.x - end.x, pose.y - end.y) <= 0.5


@pytest.mark.heavy
def test_a_person_in_a_wide_corridor_is_driven_around(tmp_path: Path) -> None:
    map_path, tree = corridor(tmp_path, 3.6), write_tree(tmp_path, TREE)
    with running_system(map_path, tree, speed=5.0, start="start") as system:
        tracker = StandInTracker(Node("tracker", "/test", context=system.context), PERSON_X, 1.8)
        states, said, closest = drive_past(system, tracker, math.inf, timeout=120)
        assert said[0].data == "arrived" and arrived_at_the_end(system)
        assert PathState.WAITING_FOR_PATH not in states
        assert not {PathState.FAILED_MOVE, PathState.FAILED_PLAN} & set(states)
        assert system.sim.navigator.replans >= 1, "it replanned around the person"
        assert closest >= 0.7, "and kept clear of them"
        assert system.sim.base.bumps == 0


@pytest.mark.heavy
def test_a_person_in_a_narrow_corridor_is_waited_for_until_they_are_gone(tmp_path: Path) -> None:
    map_path, tree = corridor(tmp_path, 2.0), write_tree(tmp_path, TREE)
    with running_system(map_path, tree, speed=5.0, start="start") as system:
        tracker = StandInTracker(Node("tracker", "/test", context=system.context), PERSON_X, 1.0)
        states, said, closest = drive_past(system, tracker, 8.0, timeout=120)
        assert said[0].data == "arrived" and arrived_at_the_end(system)
        waiting = states.index(PathState.WAITING_FOR_PATH)
        # the person may be seen before the goal is sent (the goal then starts out waiting)
        assert states[waiting - 1] in (PathState.MOVING_TO_GOAL, PathState.NOT_INITIALIZED)
        assert states[waiting + 1] == PathState.MOVING_TO_GOAL, "on again once they left"
        assert states.count(PathState.WAITING_FOR_PATH) == 1
        assert not {PathState.FAILED_MOVE, PathState.FAILED_PLAN} & set(states)
        assert closest >= 0.8, "it waited short of the person"
        # one wait, as the path states say (the navigator's own count is per goal, and MoveTo
        # may send its goal again while the robot waits); it never touched anyone
        assert system.sim.base.bumps == 0
