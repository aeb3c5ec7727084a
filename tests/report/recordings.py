"""Recordings written for the report's tests, with cyborg.record's own file writer.

:class:`RecordingWriter` writes messages on topics at chosen seconds after a fixed start, as
the recorder would have received them; :func:`mission` writes one robot's whole run whose
figures the tests know: a small map, a trajectory, battery with a charging and docked stretch,
goals reached and failed, tree ticks, detections and a /rosout warning.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from cyborg.bus import MessageTypes
from cyborg.bus.msgs.builtin_interfaces.msg import Time
from cyborg.bus.msgs.cyborg_msgs.msg import (
    BatteryStatus,
    BehaviorTree,
    BehaviorTreeStatus,
    BumperState,
    GoalWithHeading,
    MapGeometry,
    MapObject,
    Prediction,
    Predictions,
)
from cyborg.bus.msgs.geometry_msgs.msg import Point32, Polygon, Pose2D
from cyborg.bus.msgs.rcl_interfaces.msg import Log
from cyborg.bus.msgs.std_msgs.msg import Header, String
from cyborg.bus.msgs.vision_msgs.msg import (
    BoundingBox2D,
    Detection2D,
    Detection2DArray,
    ObjectHypothesis,
    ObjectHypothesisWithPose,
)
from cyborg.bus.msgs.vision_msgs.msg import Pose2D as VisionPose2D
from cyborg.record.mcap_file import McapFile
from cyborg.record.recorder import MAP_METADATA, RUN_METADATA

START_NS = 1_700_000_000_000_000_000
"""The log time of a recording's second 0."""
TYPES = MessageTypes()


class RecordingWriter:
    """An MCAP file in the rosbag2 layout, written message by message at chosen times."""

    def __init__(self, path: Path, *, compression: str = "zstd") -> None:
        self.file = McapFile(path, TYPES, compression=compression)

    def add(self, topic: str, message: Any, seconds: float) -> None:
        type_name = TYPES.type_name(type(message))
        channel = self.file.channel(topic, type_name, [])
        when = START_NS + int(seconds * 1e9)
        self.file.write(channel, when, when, bytes(TYPES.serialize(message, type_name)))

    def metadata(self, name: str, values: dict[str, str]) -> None:
        self.file.metadata(name, values)

    def close(self) -> None:
        self.file.close()


def header(seconds: float = 0.0) -> Header:
    return Header(stamp=stamp(seconds), frame_id="map")


def stamp(seconds: float) -> Time:
    return Time(sec=int(seconds), nanosec=round((seconds % 1) * 1e9))


def structure(*nodes: tuple[str, str, int]) -> str:
    """A structure's JSON from (id, label, depth) rows in pre-order (depth 0: the root)."""
    root: dict[str, Any] = {}
    stack: list[dict[str, Any]] = []
    for uid, label, depth in nodes:
        node = {"id": uid, "name": label, "label": label, "category": "action",
                "children": []}
        del stack[depth:]
        if stack:
            stack[-1]["children"].append(node)
            stack[-1]["category"] = "composite"
        else:
            root = node
        stack.append(node)
    return json.dumps({"schema": "cyborg.bt.structure/1", "title": "Patrol", "root": root})


def tick(number: int, seconds: float, root: int, visited: list[tuple[str, int]],
         durations: list[float] | None = None) -> BehaviorTreeStatus:
    return BehaviorTreeStatus(
        stamp=stamp(seconds), tick=number, duration=0.001, status=root,
        visited_ids=[uid for uid, _ in visited],
        visited_statuses=np.array([status for _, status in visited], np.uint8),
        visited_durations=np.array(durations if durations is not None
                                   else [0.002] * len(visited), np.float32),
        active_ids=[], halted_ids=[], mode="")


def battery(charge: float, *, charging: bool = False, dock: str = "UNDOCKED") -> BatteryStatus:
    return BatteryStatus(header=header(), charging_state=1 if charging else 0,
                         charge_percent=charge, voltage=25.0, charging=charging,
                         dock_state=dock)


def goal(name: str, x: float = 0.0, y: float = 0.0) -> GoalWithHeading:
    return GoalWithHeading(name=name, comment="", position=Pose2D(x=x, y=y, theta=0.0),
                           has_heading=False)


def small_map(points: int = 200) -> MapGeometry:
    angles = np.linspace(0.0, 2 * np.pi, points, endpoint=False)
    scanned = np.column_stack([5 + 4 * np.cos(angles), 5 + 4 * np.sin(angles)]).ravel()
    goal_object = MapObject(kind="Goal", category=MapObject.GOAL, name="room1",
                            description="", pose=Pose2D(x=8.0, y=2.0, theta=0.0),
                            outline=np.zeros(0, np.float32))
    dock_object = MapObject(kind="DockPioneer", category=MapObject.DOCK, name="dock",
                            description="", pose=Pose2D(x=1.0, y=1.0, theta=0.0),
                            outline=np.zeros(0, np.float32))
    return MapGeometry(header=header(), source="small.map", hash="sha256:00", resolution=0.1,
                       lines=np.array([0, 0, 10, 0, 10, 0, 10, 10], np.float32),
                       points=scanned.astype(np.float32), objects=[goal_object, dock_object])


def detections(*labels: str) -> Detection2DArray:
    found = [Detection2D(header=header(), results=[ObjectHypothesisWithPose(
        hypothesis=ObjectHypothesis(class_id=label, score=0.9), pose=_no_pose())],
        bbox=BoundingBox2D(center=VisionPose2D(position=_point(), theta=0.0), size_x=1.0,
                           size_y=1.0), id="") for label in labels]
    return Detection2DArray(header=header(), detections=found)


def predictions(*labels: str) -> Predictions:
    return Predictions(header=header(), image_header=header(), predictions=[
        Prediction(label=label, confidence=0.9, distance=1.0,
                   bounding_box=Polygon(points=[Point32(x=0.0, y=0.0, z=0.0)] * 4))
        for label in labels])


def _point() -> Any:
    from cyborg.bus.msgs.vision_msgs.msg import Point2D
    return Point2D(x=0.0, y=0.0)


def _no_pose() -> Any:
    from cyborg.bus.msgs.geometry_msgs.msg import (
        Point,
        Pose,
        PoseWithCovariance,
        Quaternion,
    )
    return PoseWithCovariance(pose=Pose(position=Point(x=0.0, y=0.0, z=0.0),
                                        orientation=Quaternion(x=0.0, y=0.0, z=0.0, w=1.0)),
                              covariance=np.zeros(36))


@dataclass
class Mission:
    """What :func:`mission` wrote, for the tests to compare the report with."""

    poses: list[tuple[float, float]] = field(default_factory=list)
    battery: list[float] = field(default_factory=list)
    reached: int = 0
    failed: int = 0


def mission(path: Path, namespace: str = "/cyborg", *, writer: RecordingWriter | None = None,
            rosout: bool = True) -> Mission:
    """One robot's run of 150 s: see the module. The tree has root r, sequence s, leaves a, b.

    Ticks 1-10: a runs (r, s running); ticks 11-12: a succeeds, b fails (s, r fail);
    ticks 13-20: a succeeds, b succeeds (all succeed), once a second from second 1.
    """
    own = writer is None
    out = writer or RecordingWriter(path)
    done = Mission()
    if own:
        out.metadata(RUN_METADATA, {"cyborg_version": "9.9", "started": "2024-01-01T10:00:00",
                                    "command": "cyborg up --record run.mcap",
                                    "map": "/maps/small.map", "tree": "/trees/patrol.json"})
        out.metadata(MAP_METADATA, {"topic": f"{namespace}/map_geometry",
                                    "source": "small.map", "hash": "sha256:00"})
    ns = namespace.rstrip("/")
    out.add(f"{ns}/map_geometry", small_map(), 0.0)
    out.add(f"{ns}/bt/behavior_tree", BehaviorTree(tree=structure(
        ("r", "Root", 0), ("s", "Sequence", 1), ("a", "MoveTo room1", 2), ("b", "Wait", 2))),
        0.0)
    for number in range(1, 21):
        if number <= 10:
            visited = [("a", 3), ("s", 3), ("r", 3)]
            root = 3
        elif number <= 12:
            visited = [("a", 1), ("b", 2), ("s", 2), ("r", 2)]
            root = 2
        else:
            visited = [("a", 1), ("b", 1), ("s", 1), ("r", 1)]
            root = 1
        out.add(f"{ns}/bt/status", tick(number, float(number), root, visited), float(number))
    for step in range(60):
        x, y = 1.0 + step * 0.1, 1.0 + (step % 10) * 0.02
        done.poses.append((x, y))
        out.add(f"{ns}/pose", Pose2D(x=x, y=y, theta=0.0), step * 2.0)
    for second in range(0, 150, 10):
        charging = 60 <= second < 100
        charge = 50.0 - second * 0.1 + (second - 60) * 0.3 * charging
        done.battery.append(charge)
        out.add(f"{ns}/battery_status", battery(charge, charging=charging,
                                                dock="DOCKED" if charging else "UNDOCKED"),
                float(second))
    for attempt, (name, outcome) in enumerate([("room1", "REACHED_GOAL"),
                                               ("room2", "FAILED_MOVE"),
                                               ("room3", "REACHED_GOAL"),
                                               ("dock", "REACHED_GOAL")]):
        began = 5.0 + attempt * 30.0
        out.add(f"{ns}/arnl_path_state", String(data="PLANNING_PATH"), began)
        out.add(f"{ns}/current_goal", goal(name, 2.0 + attempt, 3.0), began + 0.001)
        out.add(f"{ns}/arnl_path_state", String(data="MOVING_TO_GOAL"), began + 0.5)
        out.add(f"{ns}/arnl_path_state", String(data=outcome), began + 20.0)
        out.add(f"{ns}/current_goal", goal(""), began + 20.001)
        done.reached += outcome == "REACHED_GOAL"
        done.failed += outcome != "REACHED_GOAL"
    for seen_at, labels in ((10.0, ("person", "person")), (30.0, ("chair",)),
                            (70.0, ("person",)), (130.0, ("chair", "chair", "person"))):
        out.add(f"{ns}/detector/detections", detections(*labels), seen_at)
        out.add(f"{ns}/detector/predictions", predictions(*labels), seen_at)
    out.add(f"{ns}/bumper_state", BumperState(header=header(), front_bumpers=np.array([True]),
                                              rear_bumpers=np.array([False])), 50.0)
    if rosout:
        out.add("/rosout", Log(stamp=stamp(40.0), level=30, name="navigator",
                               msg="path <blocked> near room2", file="", function="",
                               line=0), 40.0)
        out.add("/rosout", Log(stamp=stamp(41.0), level=20, name="navigator", msg="replanning",
                               file="", function="", line=0), 41.0)
    if own:
        out.close()
    return done
