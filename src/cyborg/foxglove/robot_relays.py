"""What Foxglove's 3D panel needs of a robot beyond its topics: its map drawn, and where it is.

For each robot on the bus (found by its pose, :func:`cyborg.interfaces.robot.robot_namespace`)
under its namespace ``NS``:

=====================  =============================  =========================================
channel                schema                         from
=====================  =============================  =========================================
``NS/map``             nav_msgs/msg/OccupancyGrid     ``NS/map_geometry``, rasterised
                       (ros2msg, cdr)                 (:mod:`cyborg.foxglove.map_grid`)
``NS/map_scene``       foxglove.SceneUpdate           ``NS/map_geometry``: walls, forbidden
                       (protobuf)                     lines and areas, named goals
                                                      (:mod:`cyborg.foxglove.map_scene`)
``NS/pose_tf``         foxglove.FrameTransform        ``NS/odom``: its frame (``map``) to its
                       (protobuf)                     child (``base_link``), stamped as the
                                                      odometry is (simulated time under the
                                                      simulator), so the laser's scan lines up
=====================  =============================  =========================================

The map's channels are latched in effect: a client that subscribes later gets the map drawn last.
"""

from __future__ import annotations

from typing import Any

import foxglove
from foxglove.channels import FrameTransformChannel, SceneUpdateChannel
from foxglove.messages import FrameTransform, Quaternion, SceneUpdate, Timestamp, Vector3

from cyborg.bus import Node
from cyborg.bus.executor import CallbackThread
from cyborg.bus.msgs.cyborg_msgs.msg import MapGeometry
from cyborg.bus.msgs.nav_msgs.msg import Odometry
from cyborg.foxglove.derived_relay import DerivedRelay
from cyborg.foxglove.map_grid import occupancy_grid
from cyborg.foxglove.map_scene import map_scene
from cyborg.foxglove.schemas import CDR, ros2msg_schema
from cyborg.interfaces import robot
from cyborg.interfaces.contract import Topic, resolve

GRID_TYPE = "nav_msgs/msg/OccupancyGrid"
MAP_CHANNEL = "map"
"""The occupancy grid's channel, under the robot's namespace."""
SCENE_CHANNEL = "map_scene"
"""The map's scene's channel, under the robot's namespace."""
FRAME_CHANNEL = "pose_tf"
"""The robot's frame transform's channel, under the robot's namespace."""


class MapGridRelay(DerivedRelay):
    """The robot's ``map_geometry`` as an occupancy grid on ``NS/map``."""

    def __init__(self, node: Node, namespace: str, thread: CallbackThread,
                 context: foxglove.Context) -> None:
        super().__init__(resolve(namespace, MAP_CHANNEL), node, namespace,
                         (robot.MAP_GEOMETRY,), thread)
        self.channel: foxglove.Channel = foxglove.Channel(
            self.topic, schema=ros2msg_schema(node.types, GRID_TYPE), message_encoding=CDR,
            context=context)

    def convert(self, source: Topic[Any], message: MapGeometry) -> bytes:
        """The grid's CDR."""
        return bytes(self.node.types.serialize(occupancy_grid(message), GRID_TYPE))

    def write(self, result: bytes, log_time: int) -> None:
        """Log the grid's CDR."""
        self.channel.log(result, log_time=log_time)


class MapSceneRelay(DerivedRelay):
    """The robot's ``map_geometry`` as a scene update on ``NS/map_scene``."""

    channel: SceneUpdateChannel

    def __init__(self, node: Node, namespace: str, thread: CallbackThread,
                 context: foxglove.Context) -> None:
        super().__init__(resolve(namespace, SCENE_CHANNEL), node, namespace,
                         (robot.MAP_GEOMETRY,), thread)
        self.channel = SceneUpdateChannel(self.topic, context=context)

    def convert(self, source: Topic[Any], message: MapGeometry) -> SceneUpdate:
        """The scene that draws the map."""
        return map_scene(message)

    def write(self, result: SceneUpdate, log_time: int) -> None:
        """Log the scene update."""
        self.channel.log(result, log_time=log_time)


class RobotFrameRelay(DerivedRelay):
    """The robot's pose as a frame transform on ``NS/pose_tf``, from its odometry."""

    channel: FrameTransformChannel

    def __init__(self, node: Node, namespace: str, thread: CallbackThread,
                 context: foxglove.Context) -> None:
        super().__init__(resolve(namespace, FRAME_CHANNEL), node, namespace, (robot.ODOM,),
                         thread)
        self.channel = FrameTransformChannel(self.topic, context=context)

    def convert(self, source: Topic[Any], message: Odometry) -> FrameTransform:
        """``header.frame_id`` → ``child_frame_id`` (``map`` → ``base_link`` if left empty)."""
        pose = message.pose.pose
        stamp = message.header.stamp
        return FrameTransform(
            timestamp=Timestamp(int(stamp.sec), int(stamp.nanosec)),
            parent_frame_id=message.header.frame_id or robot.MAP_FRAME,
            child_frame_id=message.child_frame_id or robot.BASE_FRAME,
            translation=Vector3(x=pose.position.x, y=pose.position.y, z=pose.position.z),
            rotation=Quaternion(x=pose.orientation.x, y=pose.orientation.y,
                                z=pose.orientation.z, w=pose.orientation.w))

    def write(self, result: FrameTransform, log_time: int) -> None:
        """Log the transform."""
        self.channel.log(result, log_time=log_time)
