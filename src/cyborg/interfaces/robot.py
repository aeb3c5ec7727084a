"""The robot's ARNL-like interface, between the simulator and the robot client.

What the simulator (or a bridge to the real robot) serves and
:class:`~cyborg.robot.bus_robot.BusRobot` uses.

Under the robot's namespace (:data:`NAMESPACE`, ``/cyborg`` by default), from a node named
``arnl`` (the simulator's; rosarnl's in 2018):

==========================  ==================================  ==================================
name                        type                                what
==========================  ==================================  ==================================
``/clock``                  rosgraph_msgs/Clock                 simulated time (for use_sim_time)
``pose``                    geometry_msgs/Pose2D                the robot's pose in the map frame
``odom``                    nav_msgs/Odometry                   pose and velocity
``scan``                    sensor_msgs/LaserScan               the laser's beams
``bumper_state``            cyborg_msgs/BumperState             latched, on change
``battery_status``          cyborg_msgs/BatteryStatus           latched: :class:`ChargingState`,
                                                                charge, :class:`DockState`
``arnl_path_state``         std_msgs/String                     latched: a :class:`PathState`
``path``                    nav_msgs/Path                       latched: the path being followed
``current_goal``            cyborg_msgs/GoalWithHeading         latched: the goal being driven to
                                                                (a pose goal named by its
                                                                coordinates); an empty name when
                                                                there is none
``map_geometry``            cyborg_msgs/MapGeometry             latched: the map as displays draw
                                                                it (walls, points, objects, hash),
                                                                again after each map switch
``footprint``               geometry_msgs/PolygonStamped        latched: the robot's outline,
                                                                frame ``base_link``
``/tf_static``              tf2_msgs/TFMessage                  latched: ``base_link`` → ``laser``
                                                                (the scan's frame), as ROS does
``move_to_goal``            cyborg_msgs/action/MoveToGoal       drive to a goal name or a pose;
                                                                ends with a :class:`MoveOutcome`
``dock``, ``undock``,       std_srvs/Trigger                    docking; ``stop`` cancels the goal
``stop``
``set_pose``                cyborg_msgs/srv/SetPose             relocalise (the simulator
                                                                teleports); cancels the goal
``cmd_vel`` (subscribed)    geometry_msgs/Twist                 drive by hand: cancels the goal;
                                                                clamped to :data:`TELEOP_MAX_SPEED`
                                                                and :data:`TELEOP_MAX_TURN_RATE`;
                                                                stops :data:`TELEOP_TIMEOUT` after
                                                                the last command
``/initialpose``            geometry_msgs/                      as ``set_pose``, from RViz's and
(subscribed)                PoseWithCovarianceStamped           Foxglove's pose estimate tool
``nav/get_available_goals`` cyborg_msgs/srv/AvailableGoals      the map's named goals
``nav/get_distance_to_goal`` cyborg_msgs/srv/DistanceToGoal     planned path length to a pose
``nav/get_closest_goal``    cyborg_msgs/srv/ClosestGoal         nearest goal by path length
``make_plan``               cyborg_msgs/srv/MakePlan            a path on the static map
``load_map_file``           cyborg_msgs/srv/LoadMapFile         switch maps at runtime
==========================  ==================================  ==================================

The robot publishes the topics and serves the services; it subscribes to the
:data:`COMMANDS` (``cmd_vel``, ``/initialpose``), which others publish to act on it.

The enums' values come from the message definitions where those declare them
(BatteryStatus.msg, MoveToGoal.action); ARNL's path states exist only here.
"""

from __future__ import annotations

import math
from enum import IntEnum, StrEnum

from cyborg.bus.clock import CLOCK_TOPIC
from cyborg.bus.msgs.cyborg_msgs.action import MoveToGoal, MoveToGoal_Result
from cyborg.bus.msgs.cyborg_msgs.msg import (
    BatteryStatus,
    BumperState,
    GoalWithHeading,
    MapGeometry,
)
from cyborg.bus.msgs.cyborg_msgs.srv import (
    AvailableGoals,
    ClosestGoal,
    DistanceToGoal,
    LoadMapFile,
    MakePlan,
    SetPose,
)
from cyborg.bus.msgs.geometry_msgs.msg import (
    PolygonStamped,
    Pose2D,
    PoseWithCovarianceStamped,
    Twist,
)
from cyborg.bus.msgs.nav_msgs.msg import Odometry, Path
from cyborg.bus.msgs.rosgraph_msgs.msg import Clock
from cyborg.bus.msgs.sensor_msgs.msg import LaserScan
from cyborg.bus.msgs.std_msgs.msg import String
from cyborg.bus.msgs.std_srvs.srv import Trigger
from cyborg.bus.msgs.tf2_msgs.msg import TFMessage
from cyborg.interfaces.contract import Action, Service, Topic

NAMESPACE = "/cyborg"
"""The robot's namespace unless told otherwise."""

# ---------------------------------------------------------------------- topics
CLOCK = Topic(CLOCK_TOPIC, Clock)
POSE = Topic("pose", Pose2D)
ODOM = Topic("odom", Odometry)
SCAN = Topic("scan", LaserScan)
BUMPER_STATE = Topic("bumper_state", BumperState, latched=True)
BATTERY_STATUS = Topic("battery_status", BatteryStatus, latched=True)
PATH_STATE = Topic("arnl_path_state", String, latched=True)
PATH = Topic("path", Path, latched=True)
CURRENT_GOAL = Topic("current_goal", GoalWithHeading, latched=True)
"""rosarnl's ``current_goal``: the goal the navigator drives to, while it does.

Its ``name`` is the map goal's name, or for a pose goal the pose's coordinates as
``(x, y)`` in metres; ``position`` is where it leads, ``has_heading`` whether the robot turns
to ``position.theta`` on arrival, ``comment`` the goal's description from the map. When the
goal ends (reached, failed, cancelled, preempted) the topic says so with an empty ``name``."""
MAP_GEOMETRY = Topic("map_geometry", MapGeometry, latched=True)
FOOTPRINT = Topic("footprint", PolygonStamped, latched=True)
TF_STATIC = Topic("/tf_static", TFMessage, latched=True, depth=100)
"""Fixed transforms between the robot's frames; absolute and latched, as in ROS 2.

One topic for the whole bus: with several robots each publishes its own transforms (its frames
named after it, ``robot1/base_link``), and a subscriber that joins late gets every robot's
latched message at once; depth 100, as ROS's static transform listener keeps, so that none of
them pushes another out of its queue."""
TOPICS: tuple[Topic, ...] = (CLOCK, POSE, ODOM, SCAN, BUMPER_STATE, BATTERY_STATUS, PATH_STATE,
                             PATH, CURRENT_GOAL, MAP_GEOMETRY, FOOTPRINT, TF_STATIC)
"""The topics the robot publishes."""

CMD_VEL = Topic("cmd_vel", Twist, depth=1)
"""Drive by hand: ``linear.x`` (m/s, forward) and ``angular.z`` (rad/s, counter-clockwise).

Each command cancels the goal (and docking) and holds until the next one; a zero twist stops
the robot. Speeds are clamped to :data:`TELEOP_MAX_SPEED` and :data:`TELEOP_MAX_TURN_RATE`; a
twist holding a NaN or an infinity is ignored. The robot never drives into what it knows
(walls, its laser's returns): it slows and stops instead. It stops by itself
:data:`TELEOP_TIMEOUT` wall-clock seconds after the last command, so a sender sends again
(10 Hz) while the robot should move. Depth 1: only the newest command matters."""
INITIAL_POSE = Topic("/initialpose", PoseWithCovarianceStamped)
"""Relocalise, as RViz's "2D Pose Estimate" and Foxglove's pose estimate publish it: absolute,
in the ``map`` frame (an empty ``frame_id`` counts as ``map``), the heading from the
quaternion, the covariance ignored. The same as :data:`SET_POSE`; refusals are logged."""
COMMANDS: tuple[Topic, ...] = (CMD_VEL, INITIAL_POSE)
"""The topics the robot subscribes to: others publish them to act on it."""

TELEOP_MAX_SPEED = 0.5
"""The fastest a ``cmd_vel`` command drives the robot, m/s (forwards or backwards)."""
TELEOP_MAX_TURN_RATE = 1.0
"""The fastest a ``cmd_vel`` command turns the robot, rad/s."""
TELEOP_TIMEOUT = 0.5
"""Wall-clock seconds after the last ``cmd_vel`` command at which the robot stops (deadman).

Wall clock, not simulated time: the commands come from a person at the pace of the wall
clock, and a simulation running 30 times faster would otherwise stop the robot between two
of a 10 Hz sender's commands (MobileEyes' ratioDrive waits 2 s the same way)."""

def yaw_of(x: float, y: float, z: float, w: float) -> float:
    """The heading (rad) that the quaternion ``(x, y, z, w)`` turns about z.

    ``odom`` and tf carry the robot's heading this way; the quaternion need not be normalised.
    """
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


BASE_FRAME = "base_link"
"""The robot's frame: x forward, y left, origin on the drive axle."""
LASER_FRAME = "laser"
"""The laser scanner's frame: the ``scan``'s ``frame_id``, a child of :data:`BASE_FRAME`."""
MAP_FRAME = "map"
"""The map's frame: poses, paths and ``map_geometry`` are in it."""

# ---------------------------------------------------------------------- services and the action
DOCK = Service("dock", Trigger)
UNDOCK = Service("undock", Trigger)
STOP = Service("stop", Trigger)
AVAILABLE_GOALS = Service("nav/get_available_goals", AvailableGoals)
DISTANCE_TO_GOAL = Service("nav/get_distance_to_goal", DistanceToGoal)
CLOSEST_GOAL = Service("nav/get_closest_goal", ClosestGoal)
MAKE_PLAN = Service("make_plan", MakePlan)
LOAD_MAP_FILE = Service("load_map_file", LoadMapFile)
SET_POSE = Service("set_pose", SetPose)
"""Relocalise: the robot stands at ``pose`` (the simulator teleports it there, standing still).

Any goal, docking and driving by hand end first. Refused (``success`` false, ``message``
saying why, nothing changed) when the pose is not finite, off the map, or when the body there
would overlap a wall, an obstacle or a forbidden area or line."""
SERVICES: tuple[Service, ...] = (DOCK, UNDOCK, STOP, AVAILABLE_GOALS, DISTANCE_TO_GOAL,
                                  CLOSEST_GOAL, MAKE_PLAN, LOAD_MAP_FILE, SET_POSE)
NAVIGATION_SERVICES: tuple[Service, ...] = (AVAILABLE_GOALS, DISTANCE_TO_GOAL, CLOSEST_GOAL,
                                             MAKE_PLAN, LOAD_MAP_FILE)
"""The services of :mod:`cyborg.nav.services`, answered on the map in use."""

MOVE_TO_GOAL = Action("move_to_goal", MoveToGoal)

FLEET_ROBOT = "robot"
"""What a fleet's robots are called: ``robot1``, ``robot2``, ... (:func:`fleet_namespaces`)."""


def fleet_namespaces(base: str, count: int) -> list[str]:
    """The namespaces of ``count`` robots under ``base``: a robot alone keeps ``base``.

    Several are ``<base>/robot1`` … ``<base>/robotN``: ``/robot1`` … under ``/``, each robot's
    tree runner then under ``/robot1/bt`` (:func:`cyborg.interfaces.tree_runner.robot_of_runner`
    pairs them back).
    """
    if count == 1:
        return [base]
    prefix = "/" + base.strip("/")
    return [f"{prefix.rstrip('/')}/{FLEET_ROBOT}{index}" for index in range(1, count + 1)]


def robot_namespace(topic: str, type_name: str) -> str | None:
    """The namespace of the robot that publishes ``topic`` of ``type_name``, or None.

    Robots are found by their pose (``/robot1/pose`` of type Pose2D → ``/robot1``); any other
    topic names none. ``type_name`` is the topic's type as the bus graph shows it.
    """
    suffix = "/" + POSE.name
    if type_name != POSE.type_name or not topic.endswith(suffix):
        return None
    return topic.removesuffix(suffix) or "/"


# ---------------------------------------------------------------------- values in the messages


class MoveOutcome(IntEnum):
    """How a move ended: MoveToGoal's result ``outcome``."""

    SUCCEEDED = MoveToGoal_Result.SUCCEEDED
    FAILED = MoveToGoal_Result.FAILED
    """Gave up on the way (stalled, blocked, preempted): trying again may help."""
    CANCELED = MoveToGoal_Result.CANCELED
    NO_PATH = MoveToGoal_Result.NO_PATH
    """No such goal or no path to it: trying again will not help."""


class DockState(StrEnum):
    """BatteryStatus ``dock_state``: where docking stands (ARNL's states)."""

    UNDOCKED = BatteryStatus.DOCK_UNDOCKED
    DOCKING = BatteryStatus.DOCK_DOCKING
    DOCKED = BatteryStatus.DOCK_DOCKED
    UNDOCKING = BatteryStatus.DOCK_UNDOCKING
    UNKNOWN = ""
    """Not one of the states (a client's reading of a value it does not know)."""


class ChargingState(IntEnum):
    """BatteryStatus ``charging_state`` (rosarnl's numbers)."""

    UNKNOWN = BatteryStatus.CHARGING_UNKNOWN
    NOT = BatteryStatus.CHARGING_NOT
    BULK = BatteryStatus.CHARGING_BULK
    OVERCHARGE = BatteryStatus.CHARGING_OVERCHARGE
    FLOAT = BatteryStatus.CHARGING_FLOAT
    BALANCE = BatteryStatus.CHARGING_BALANCE


class PathState(StrEnum):
    """What ``arnl_path_state`` says: ARNL's path planning states, and one of cyborg's.

    ``WAITING_FOR_PATH`` is not ARNL's: the goal is still on, but the only ways to it run
    through objects seen lately (a person in a narrow corridor,
    :mod:`cyborg.nav.temporary_obstacles`); the robot stands and plans again now and then
    until a way opens, and goes on ``MOVING_TO_GOAL``.
    """

    NOT_INITIALIZED = "NOT_INITIALIZED"
    PLANNING_PATH = "PLANNING_PATH"
    MOVING_TO_GOAL = "MOVING_TO_GOAL"
    WAITING_FOR_PATH = "WAITING_FOR_PATH"
    REACHED_GOAL = "REACHED_GOAL"
    FAILED_PLAN = "FAILED_PLAN"
    FAILED_MOVE = "FAILED_MOVE"
    ABORTED_PATHPLAN = "ABORTED_PATHPLAN"
    INVALID = "INVALID"

    @property
    def finished(self) -> bool:
        """Whether the path is over, reached or not: all but planning, moving and waiting."""
        return self not in (PathState.PLANNING_PATH, PathState.MOVING_TO_GOAL,
                            PathState.WAITING_FOR_PATH)
