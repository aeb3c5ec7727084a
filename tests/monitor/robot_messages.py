"""Helpers for the map data path's tests: a robot's messages built by hand (pose, scan, path,
battery, current goal, footprint, fixed transforms, map geometry, the detector's detections
and predictions, the tracker's objects), and a fake robot that publishes them on a bus."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from cyborg.bus import Node
from cyborg.bus.msgs.builtin_interfaces.msg import Time
from cyborg.bus.msgs.cyborg_msgs.msg import (
    BatteryStatus,
    GoalWithHeading,
    MapGeometry,
    MapObject,
    Prediction,
    Predictions,
    TrackedObject,
    TrackedObjects,
)
from cyborg.bus.msgs.geometry_msgs.msg import (
    Point,
    Point32,
    Polygon,
    PolygonStamped,
    Pose,
    Pose2D,
    PoseStamped,
    PoseWithCovariance,
    Quaternion,
    Transform,
    TransformStamped,
    Vector3,
)
from cyborg.bus.msgs.nav_msgs.msg import Path
from cyborg.bus.msgs.sensor_msgs.msg import LaserScan
from cyborg.bus.msgs.std_msgs.msg import Header, String
from cyborg.bus.msgs.tf2_msgs.msg import TFMessage
from cyborg.bus.msgs.vision_msgs.msg import (
    BoundingBox2D,
    Detection2D,
    Detection2DArray,
    ObjectHypothesis,
    ObjectHypothesisWithPose,
    Point2D,
)
from cyborg.bus.msgs.vision_msgs.msg import Pose2D as VisionPose2D
from cyborg.interfaces import detector, perception, robot

BEAMS = 541
INCREMENT = math.radians(0.5)


def header(frame: str = "map") -> Header:
    return Header(stamp=Time(sec=0, nanosec=0), frame_id=frame)


def pose(x: float = 1.0, y: float = 2.0, theta: float = 0.5) -> Pose2D:
    return Pose2D(x=x, y=y, theta=theta)


def scan(ranges: Sequence[float] | np.ndarray | None = None, *, beams: int = BEAMS,
         angle_min: float = -math.radians(135), increment: float = INCREMENT,
         angle_max: float | None = None, range_min: float = 0.1,
         range_max: float = 30.0) -> LaserScan:
    """A scan of ``beams`` beams (all 5 m unless ``ranges`` says otherwise)."""
    values = np.full(beams, 5.0, np.float32) if ranges is None else np.asarray(ranges,
                                                                               np.float32)
    if angle_max is None:
        angle_max = angle_min + increment * (beams - 1)
    return LaserScan(header=header("laser"), angle_min=angle_min, angle_max=angle_max,
                     angle_increment=increment, time_increment=0.0, scan_time=0.1,
                     range_min=range_min, range_max=range_max, ranges=values,
                     intensities=np.zeros(0, np.float32))


def path(points: Sequence[tuple[float, float]]) -> Path:
    return Path(header=header(), poses=[
        PoseStamped(header=header(), pose=Pose(position=Point(x=x, y=y, z=0.0),
                                               orientation=Quaternion(x=0.0, y=0.0, z=0.0,
                                                                      w=1.0)))
        for x, y in points])


def battery(charge: float = 80.0, dock: str = "UNDOCKED") -> BatteryStatus:
    return BatteryStatus(header=header("base_link"), charging_state=0, charge_percent=charge,
                         voltage=25.0, charging=False, dock_state=dock)


def goal(name: str = "Office", x: float = 1.0, y: float = 2.0, theta: float = 0.5, *,
         heading: bool = True) -> GoalWithHeading:
    """``current_goal``'s message: the goal ``name`` at ``(x, y)``; "" for no goal."""
    return GoalWithHeading(name=name, comment="", position=Pose2D(x=x, y=y, theta=theta),
                           has_heading=heading)


def footprint(corners: Sequence[tuple[float, float]] = ((0.3, 0.2), (-0.3, 0.2), (-0.3, -0.2),
                                                       (0.3, -0.2))) -> PolygonStamped:
    """An outline in the robot's frame (a 60 x 40 cm box unless told)."""
    return PolygonStamped(header=header("base_link"), polygon=Polygon(points=[
        Point32(x=x, y=y, z=0.0) for x, y in corners]))


def transforms(*links: tuple[str, str, float, float, float]) -> TFMessage:
    """``/tf_static``'s message: ``(parent, child, x, y, yaw)`` per transform (a yaw that is not
    finite goes into the quaternion as it is)."""
    def rotation(yaw: float) -> Quaternion:
        if not math.isfinite(yaw):
            return Quaternion(x=0.0, y=0.0, z=yaw, w=yaw)
        return Quaternion(x=0.0, y=0.0, z=math.sin(yaw / 2), w=math.cos(yaw / 2))

    return TFMessage(transforms=[
        TransformStamped(header=header(parent), child_frame_id=child, transform=Transform(
            translation=Vector3(x=x, y=y, z=0.1), rotation=rotation(yaw)))
        for parent, child, x, y, yaw in links])


def map_object(name: str = "Office", category: int = MapObject.GOAL, kind: str = "Goal",
               at: tuple[float, float, float] = (1.0, 2.0, 0.0),
               outline: Sequence[float] = ()) -> MapObject:
    return MapObject(kind=kind, category=category, name=name, description="",
                     pose=Pose2D(x=at[0], y=at[1], theta=at[2]),
                     outline=np.asarray(outline, np.float32))


def map_geometry(lines: Sequence[float] | np.ndarray = (0.0, 0.0, 10.0, 0.0, 10.0, 0.0, 10.0,
                                                        5.0),
                 points: Sequence[float] | np.ndarray = (1.0, 1.0, 2.5, 3.0, -1.0, 4.0),
                 objects: Sequence[MapObject] | None = None, source: str = "small.map",
                 hash_: str = "sha256:feed") -> MapGeometry:
    """A small map: two walls, three points, a goal and a forbidden area (unless told)."""
    if objects is None:
        objects = [map_object(), map_object("no go", MapObject.FORBIDDEN_AREA, "ForbiddenArea",
                                            (5.0, 1.0, 0.0),
                                            (4.0, 0.0, 6.0, 0.0, 6.0, 2.0, 4.0, 2.0))]
    return MapGeometry(header=header(), source=source, hash=hash_, resolution=0.05,
                       lines=np.asarray(lines, np.float32),
                       points=np.asarray(points, np.float32), objects=list(objects))


def detections(*objects: tuple[str, float, float], frame: str = "camera_left"
               ) -> Detection2DArray:
    """The detector's ``detections``: ``(class, score, distance)`` per object, boxes made up."""
    return Detection2DArray(header=header(frame), detections=[Detection2D(
        header=header(frame), results=[ObjectHypothesisWithPose(
            hypothesis=ObjectHypothesis(class_id=label, score=score),
            pose=PoseWithCovariance(pose=Pose(position=Point(x=0.0, y=0.0, z=distance),
                                              orientation=Quaternion(x=0.0, y=0.0, z=0.0,
                                                                     w=1.0)),
                                    covariance=np.zeros(36, np.float64)))],
        bbox=BoundingBox2D(center=VisionPose2D(position=Point2D(x=320.0, y=240.0), theta=0.0),
                           size_x=40.0, size_y=80.0), id=str(index))
        for index, (label, score, distance) in enumerate(objects)])


def predictions(*objects: tuple[str, float, float], frame: str = "camera_left") -> Predictions:
    """The detector's 2018 ``predictions``: ``(label, confidence, distance)`` per object."""
    return Predictions(header=header(frame), image_header=header(frame), predictions=[
        Prediction(label=label, confidence=score, distance=distance, bounding_box=Polygon(
            points=[Point32(x=x, y=y, z=0.0) for x, y in ((0, 0), (9, 0), (9, 9), (0, 9))]))
        for label, score, distance in objects])


def stamp(seconds: float) -> Time:
    """A ``builtin_interfaces/Time`` of ``seconds`` (0 or more)."""
    whole = int(seconds)
    return Time(sec=whole, nanosec=round((seconds - whole) * 1e9))


def tracked(id_: int, label: str = "person", at: tuple[float, float] = (1.0, 2.0),
            velocity: tuple[float, float] = (0.0, 0.0), *, confidence: float = 0.8,
            last_seen: float = 10.0, times_seen: int = 3) -> TrackedObject:
    """One object the tracker follows, at ``at`` (m, map frame), last seen at ``last_seen`` s."""
    return TrackedObject(id=id_, label=label, confidence=confidence,
                         position=Point(x=at[0], y=at[1], z=0.0),
                         velocity=Vector3(x=velocity[0], y=velocity[1], z=0.0),
                         last_seen=stamp(last_seen), times_seen=times_seen, distance=2.0,
                         bearing=0.1)


def tracked_objects(*objects: TrackedObject, now: float = 10.0,
                    frame: str = "map") -> TrackedObjects:
    """The tracker's ``objects`` message as of ``now`` s."""
    return TrackedObjects(header=Header(stamp=stamp(now), frame_id=frame), objects=list(objects))


class FakeMapRobot:
    """Publishes a robot's topics under ``namespace`` on ``node``'s bus, by hand."""

    def __init__(self, node: Node, namespace: str = "/robot1") -> None:
        self.node, self.namespace = node, namespace
        self.pose = robot.POSE.publisher(node, namespace)
        self.scan = robot.SCAN.publisher(node, namespace)
        self.path = robot.PATH.publisher(node, namespace)
        self.path_state = robot.PATH_STATE.publisher(node, namespace)
        self.battery = robot.BATTERY_STATUS.publisher(node, namespace)
        self.map = robot.MAP_GEOMETRY.publisher(node, namespace)
        self.footprint = robot.FOOTPRINT.publisher(node, namespace)
        self.goal = robot.CURRENT_GOAL.publisher(node, namespace)
        seeing = detector.detector_of_robot(namespace)
        self.detections = detector.DETECTIONS.publisher(node, seeing)
        self.predictions = detector.PREDICTIONS.publisher(node, seeing)
        self.objects = perception.OBJECTS.publisher(node, namespace)
        self.tf_static = robot.TF_STATIC.publisher(node)

    def state(self, text: str) -> None:
        self.path_state.publish(String(data=text))
