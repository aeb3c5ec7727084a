"""One robot, followed over the bus for the page's map: its topics in, checked, the latest kept.

A :class:`RobotSource` subscribes, under the robot's namespace (``/cyborg`` by default; the
names are those of :mod:`cyborg.interfaces.robot`), to ``pose``, ``scan``, ``path``,
``arnl_path_state``, ``battery_status``, ``current_goal``, ``footprint`` and ``map_geometry``,
and to the absolute ``/tf_static``. Its bus callbacks run on the monitor node's thread and
only check, store and notify: each message goes through its function in
:mod:`cyborg.monitor.robot_wire`, the result replaces the one kept (a message that cannot be
drawn leaves it as it was), any warning goes to the robot's :class:`WarningLog`, and the
listener hears ``listener(namespace, what)`` (``"pose"``, ``"scan"``, ``"path"``,
``"state"``, ``"battery"``, ``"goal"``, ``"footprint"``, ``"map"``, ``"warn"``, ``"alive"``,
``"det"``, ``"obj"``).
The map is kept as the message itself: laying it out and compressing it is the hub's work,
off the bus thread
(:mod:`cyborg.monitor.map_store`).

Each scan carries the laser's mount on the robot (``"m"``, see
:func:`~cyborg.monitor.robot_wire.mount_of`): the ``/tf_static`` transform whose child frame is
the scan's ``frame_id``, chained up to the robot's frame. ``/tf_static`` is one topic for the
whole bus, so every robot's source hears every robot's transforms; frames are told apart by
name only (the latest transform to a child frame wins), as in ROS without per-robot frame
prefixes. Until the transform is known a scan goes without ``"m"`` (the page draws it from the
robot's centre); after :data:`MOUNT_GRACE` such scans that is a warning, once per frame.

What the robot sees is followed only on demand (:meth:`RobotSource.follow_detections`,
:meth:`RobotSource.follow_objects`: while some page shows the map): its detector's detections,
placed on the map here (:mod:`cyborg.monitor.detection_wire`), and its tracker's ``objects``,
already on the map (:mod:`cyborg.monitor.object_wire`).

Liveness comes from the bus graph: the robot is alive while something publishes its pose.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable
from typing import Any

from cyborg.bus import Node, Qos, Subscription
from cyborg.bus.msgs.cyborg_msgs.msg import (
    BatteryStatus,
    GoalWithHeading,
    MapGeometry,
    Predictions,
    TrackedObjects,
)
from cyborg.bus.msgs.geometry_msgs.msg import PolygonStamped, Pose2D
from cyborg.bus.msgs.nav_msgs.msg import Path
from cyborg.bus.msgs.sensor_msgs.msg import LaserScan
from cyborg.bus.msgs.std_msgs.msg import String
from cyborg.bus.msgs.tf2_msgs.msg import TFMessage
from cyborg.bus.msgs.vision_msgs.msg import Detection2DArray
from cyborg.bus.wire import EntityKind
from cyborg.interfaces import detector, perception, robot
from cyborg.monitor.detection_wire import Found, detections_wire, place, predictions_wire
from cyborg.monitor.object_wire import objects_wire
from cyborg.monitor.robot_warnings import WarningLog
from cyborg.monitor.robot_wire import (
    FRAMES_KEPT,
    Transforms,
    Warnings,
    battery_wire,
    clip_text,
    footprint_wire,
    goal_wire,
    mount_of,
    path_wire,
    pose_wire,
    scan_wire,
    state_wire,
    transforms_wire,
)

log = logging.getLogger("cyborg.monitor")

Listener = Callable[[str, str], None]
"""``listener(namespace, what)``."""

PREFER_DETECTIONS = 2.0
"""Seconds after a ``detections`` message during which ``predictions`` (the same objects, in
the 2018 message) are ignored; a detector that publishes only those is followed through them."""
MOUNT_GRACE = 20
"""Scans without a known mount (``/tf_static`` may come after the first scans) before that is
a warning."""


class RobotSource:
    """Follows the robot under ``namespace``; see the module docstring."""

    def __init__(self, node: Node, namespace: str, listener: Listener) -> None:
        self.node, self.namespace = node, "/" + namespace.strip("/")
        self._listener = listener
        self.pose: list[float] | None = None
        """The last good pose, ``[x, y, θ]`` (see :func:`~robot_wire.pose_wire`)."""
        self.scan: dict[str, Any] | None = None
        self.path: dict[str, Any] | None = None
        """The latest path, ``{"id", "xy"}``: ``id`` counts the path messages (from 1), the
        page's name for the path it has."""
        self.state: str | None = None
        """``arnl_path_state``'s text."""
        self.battery: dict[str, Any] | None = None
        self.goal: dict[str, Any] | None = None
        """The goal the robot drives to, ``{"name", "p", "h"}``; None when it has none."""
        self.footprint: list[float] | None = None
        """The robot's outline, ``[x0, y0, x1, y1, ...]`` (m, its own frame)."""
        self.footprint_id = 0
        """Counts the footprints that changed the one kept: the hub sends it when this grows."""
        self.detections: dict[str, Any] | None = None
        """What the robot's detector saw last, placed on the map: ``{"id", "d"}`` (``d`` as
        :func:`~cyborg.monitor.detection_wire.place` gives it); ``id`` counts them from 1."""
        self._detections_at = -float("inf")
        self._detector: list[Subscription[Any]] = []
        self.objects: dict[str, Any] | None = None
        """What the robot's tracker follows, checked: ``{"id", "stamp", "o", "at"}`` (``o`` as
        :func:`~cyborg.monitor.object_wire.objects_wire` gives it, ``at`` when it came,
        monotonic s); ``id`` counts them from 1. None while not followed."""
        self.objects_id = 0
        """Counts the tracker's messages taken (it goes on across :meth:`follow_objects`)."""
        self._tracker: Subscription[Any] | None = None
        self.warnings = WarningLog()
        self._transforms: Transforms = {}
        self._unmounted: dict[str, int] = {}
        """Scans received per frame whose mount was not known yet (-1: warned)."""
        self.alive = False
        self._map: MapGeometry | None = None
        self._changes: set[str] = set()
        self._lock = threading.Lock()
        ns = self.namespace
        fresh = Qos(depth=2)  # the newest pose and scan are all that matter
        self._subscriptions: list[Subscription[Any]] = [
            robot.POSE.subscription(node, self._on_pose, ns, qos=fresh),
            robot.SCAN.subscription(node, self._on_scan, ns, qos=fresh),
            robot.PATH.subscription(node, self._on_path, ns),
            robot.PATH_STATE.subscription(node, self._on_state, ns),
            robot.BATTERY_STATUS.subscription(node, self._on_battery, ns),
            robot.CURRENT_GOAL.subscription(node, self._on_goal, ns),
            robot.FOOTPRINT.subscription(node, self._on_footprint, ns),
            robot.TF_STATIC.subscription(node, self._on_transforms),
            robot.MAP_GEOMETRY.subscription(node, self._on_map, ns),
        ]
        self._remove_graph_listener = node.context.graph.on_change(self._check_alive)
        self._check_alive()

    # ------------------------------------------------------------------ topics in
    def _on_pose(self, message: Pose2D) -> None:
        pose, warnings = pose_wire(message)
        self._warn("pose", warnings)
        if pose is not None:
            self.pose = pose
            self._mark("pose")

    def _on_scan(self, message: LaserScan) -> None:
        scan, warnings = scan_wire(message)
        self._warn("scan", warnings)
        if scan is not None:
            frame, _clipped = clip_text(message.header.frame_id)
            mount = mount_of(frame, self._transforms)
            if mount is not None:
                scan["m"] = mount
            else:
                self._no_mount(frame)
            self.scan = scan
            self._mark("scan")

    def _no_mount(self, frame: str) -> None:
        seen = self._unmounted.get(frame, 0)
        if seen < 0:
            return
        if seen + 1 < MOUNT_GRACE:
            self._unmounted[frame] = seen + 1
            return
        self._unmounted[frame] = -1
        self.warn("scan", f"scan: no /tf_static transform to its frame {frame!r}; drawn from "
                          "the robot's centre")

    def _on_footprint(self, message: PolygonStamped) -> None:
        footprint, warnings = footprint_wire(message)
        self._warn("footprint", warnings)
        if footprint is not None and footprint != self.footprint:
            self.footprint = footprint
            self.footprint_id += 1
            self._mark("footprint")

    def _on_transforms(self, message: TFMessage) -> None:
        transforms, warnings = transforms_wire(message)
        self._warn("tf", warnings)
        merged = {**self._transforms, **transforms}
        self._transforms = merged if len(merged) <= FRAMES_KEPT else transforms

    def _on_path(self, message: Path) -> None:
        path, warnings = path_wire(message)
        self._warn("path", warnings)
        self.path = {"id": self.path_id + 1, **path}
        self._mark("path")

    def _on_state(self, message: String) -> None:
        state, warnings = state_wire(message.data)
        self._warn("state", warnings)
        self.state = state
        self._mark("state")

    def _on_battery(self, message: BatteryStatus) -> None:
        battery, warnings = battery_wire(message)
        self._warn("battery", warnings)
        if battery is not None:
            self.battery = battery
            self._mark("battery")

    def _on_goal(self, message: GoalWithHeading) -> None:
        goal, warnings = goal_wire(message)
        self._warn("goal", warnings)
        if goal != self.goal:
            self.goal = goal
            self._mark("goal")

    def _on_map(self, message: MapGeometry) -> None:
        with self._lock:
            self._map = message
        self._mark("map")

    def follow_detections(self, on: bool) -> None:
        """Subscribes to the robot's detector (``on``), or withdraws from it.

        The detector is under ``/robot1/detector`` for ``/robot1``
        (:func:`~cyborg.interfaces.detector.detector_of_robot`); its ``detections`` are read,
        and its 2018 ``predictions`` when no ``detections`` came for :data:`PREFER_DETECTIONS`
        s. Call it from one thread only (the hub's loop).
        """
        if on == bool(self._detector):
            return
        if not on:
            for subscription in self._detector:
                subscription.destroy()
            self._detector = []
            return
        ns = detector.detector_of_robot(self.namespace)
        self._detector = [
            detector.DETECTIONS.subscription(self.node, self._on_detections, ns),
            detector.PREDICTIONS.subscription(self.node, self._on_predictions, ns),
        ]

    def _on_detections(self, message: Detection2DArray) -> None:
        self._detections_at = time.monotonic()
        self._place(*detections_wire(message))

    def _on_predictions(self, message: Predictions) -> None:
        if time.monotonic() - self._detections_at >= PREFER_DETECTIONS:
            self._place(*predictions_wire(message))

    def _place(self, found: list[Found], frame: str, warnings: Warnings) -> None:
        self._warn("detections", warnings)
        pose = self.pose
        if pose is None:
            return  # nowhere to place them yet
        mount = mount_of(frame, self._transforms) if frame else None
        self.detections = {"id": self.detections_id + 1, "d": place(found, pose, mount)}
        self._mark("det")

    def follow_objects(self, on: bool) -> None:
        """Subscribes to the robot's tracked ``objects`` (``on``), or withdraws and forgets them.

        Call it from one thread only (the hub's loop).
        """
        if on == (self._tracker is not None):
            return
        if on:
            self._tracker = perception.OBJECTS.subscription(self.node, self._on_objects,
                                                            self.namespace)
            return
        assert self._tracker is not None
        self._tracker.destroy()
        self._tracker, self.objects = None, None

    def _on_objects(self, message: TrackedObjects) -> None:
        found, warnings = objects_wire(message)
        self._warn("objects", warnings)
        if found is None or self._tracker is None:
            return
        self.objects_id += 1
        stamp = message.header.stamp
        self.objects = {"id": self.objects_id, "o": found, "at": time.monotonic(),
                        "stamp": round(float(stamp.sec) + float(stamp.nanosec) * 1e-9, 3)}
        self._mark("obj")

    def _check_alive(self) -> None:
        alive = self.node.context.graph.count(robot.POSE.full_name(self.namespace),
                                              EntityKind.PUBLISHER) > 0
        if alive != self.alive:
            self.alive = alive
            self._mark("alive")

    # ------------------------------------------------------------------ to the hub
    @property
    def path_id(self) -> int:
        """The latest path's id; 0 before the first."""
        path = self.path
        return int(path["id"]) if path is not None else 0

    @property
    def detections_id(self) -> int:
        """The latest detections' id; 0 before the first."""
        seen = self.detections
        return int(seen["id"]) if seen is not None else 0

    def _warn(self, kind: str, warnings: Warnings) -> None:
        for message in warnings:
            self.warn(kind, message)

    def warn(self, kind: str, message: str) -> None:
        """Records a warning about this robot (from any thread) and tells the listener."""
        self.warnings.add(kind, message)
        self._mark("warn")

    def _mark(self, what: str) -> None:
        with self._lock:
            self._changes.add(what)
        try:
            self._listener(self.namespace, what)
        except Exception:
            log.exception("monitor listener failed on %s %s", self.namespace, what)

    def take_changes(self) -> set[str]:
        """What changed since the last call (the kinds the listener heard of)."""
        with self._lock:
            changes, self._changes = self._changes, set()
        return changes

    def take_map(self) -> MapGeometry | None:
        """The map message received since the last call, or None; the source lets go of it."""
        with self._lock:
            message, self._map = self._map, None
        return message

    def destroy(self) -> None:
        """Withdraws the subscriptions; the listener hears nothing more."""
        self._remove_graph_listener()
        self.follow_detections(False)
        self.follow_objects(False)
        for subscription in self._subscriptions:
            subscription.destroy()
        self._subscriptions = []
        self._listener = _ignore
        with self._lock:
            self._map = None


def _ignore(_namespace: str, _what: str) -> None:
    """The listener of a source that was destroyed."""
