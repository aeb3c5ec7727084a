"""A small recorded run for the timeline's tests: a tree whose statuses change halfway, a robot
that drives along x, and its map, written as the recorder writes them (the tree's structure and
the map latched), to be played with the player.

With ``machine`` (a mode machine's JSON) the run also has the runner's mode state, the mode
``normal`` current, as a runner of a mode file latches it.

The tree is ``root`` (a sequence) over ``work`` and ``rest``. For :data:`DURATION` seconds it
ticks every :data:`PERIOD`: before :data:`HALF` ``work`` is RUNNING; from then on ``work``
succeeds and ``rest`` is RUNNING. The robot's pose is ``x`` = the second it was recorded at.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from cyborg.bus import MessageTypes
from cyborg.bus.msgs.builtin_interfaces.msg import Time
from cyborg.bus.msgs.cyborg_msgs.msg import (
    BehaviorTree,
    BehaviorTreeStatus,
    MapGeometry,
    ModeState,
)
from cyborg.bus.msgs.geometry_msgs.msg import Pose2D
from cyborg.bus.msgs.std_msgs.msg import Header
from cyborg.record.mcap_file import McapFile

TREE = "/cyborg/bt"
ROBOT = "/cyborg"
DURATION = 4.0
HALF = 2.0
PERIOD = 0.1
START_NS = 1_700_000_000_000_000_000
"""The log time of the run's second 0."""
LATCHED = "1:1:1,1:,:,:,,"
"""The rmw_zenoh QoS of a latched publisher (transient local, depth 1)."""
RUNNING, SUCCESS = 3, 1
STRUCTURE = json.dumps({"schema": "cyborg.bt.structure/1", "title": "Shift", "root": {
    "id": "root", "name": "Sequence", "label": "Shift", "category": "composite", "children": [
        {"id": "work", "name": "Work", "label": "Work", "category": "action", "children": []},
        {"id": "rest", "name": "Rest", "label": "Rest", "category": "action", "children": []},
    ]}})


def statuses_at(seconds: float) -> dict[str, int]:
    """What the tree's nodes returned in the tick recorded at ``seconds``."""
    if seconds < HALF:
        return {"work": RUNNING, "root": RUNNING}
    return {"work": SUCCESS, "rest": RUNNING, "root": RUNNING}


def _stamp(seconds: float) -> Time:
    return Time(sec=int(seconds), nanosec=round((seconds % 1) * 1e9))


def write_played_run(path: Path, machine: str = "") -> None:
    """Writes the run (see the module) to ``path``; with the mode state of ``machine``."""
    types = MessageTypes()
    file = McapFile(path, types)

    def add(topic: str, message: object, seconds: float, qos: list[str]) -> None:
        type_name = types.type_name(type(message))
        channel = file.channel(topic, type_name, qos)
        when = START_NS + round(seconds * 1e9)
        file.write(channel, when, when, bytes(types.serialize(message, type_name)))

    add(f"{TREE}/behavior_tree", BehaviorTree(tree=STRUCTURE), 0.0, [LATCHED])
    if machine:
        add(f"{TREE}/mode", ModeState(entered=_stamp(0.0), mode="normal", held=False,
                                      transitions=0, machine=machine, problems=[]),
            0.0, [LATCHED])
    add(f"{ROBOT}/map_geometry", MapGeometry(
        header=Header(stamp=_stamp(0.0), frame_id="map"), source="square.map", hash="",
        resolution=0.1, lines=np.array([-1, -1, 6, -1, 6, -1, 6, 3], np.float32),
        points=np.zeros(0, np.float32), objects=[]), 0.0, [LATCHED])
    for number in range(1, round(DURATION / PERIOD) + 1):
        seconds = number * PERIOD
        visited = statuses_at(seconds)
        add(f"{TREE}/status", BehaviorTreeStatus(
            stamp=_stamp(seconds), tick=number, duration=0.001, status=visited["root"],
            visited_ids=list(visited), visited_statuses=np.array(list(visited.values()),
                                                                  np.uint8),
            visited_durations=np.full(len(visited), 0.001, np.float32),
            active_ids=[uid for uid in ("root", "work", "rest")
                        if visited.get(uid) == RUNNING],
            halted_ids=[], mode=""), seconds, [])
        add(f"{ROBOT}/pose", Pose2D(x=seconds, y=1.0, theta=0.0), seconds, [])
    file.close()
