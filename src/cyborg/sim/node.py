"""The simulated robot on the bus, with an ARNL-like interface (as rosarnl offered in 2018).

Under the robot's namespace (``/cyborg`` by default), node ``arnl``, it serves the contract of
:mod:`cyborg.interfaces.robot`:

==========================  ==================================  ==================================
name                        type                                what
==========================  ==================================  ==================================
``/clock``                  rosgraph_msgs/Clock                 simulated time (for use_sim_time)
``pose``                    geometry_msgs/Pose2D                the robot's pose in the map frame
``odom``                    nav_msgs/Odometry                   pose and velocity
``scan``                    sensor_msgs/LaserScan               541 beams over 270 degrees
``bumper_state``            cyborg_msgs/BumperState             latched, on change
``battery_status``          cyborg_msgs/BatteryStatus           latched, every simulated second
``arnl_path_state``         std_msgs/String                     latched, on change
``path``                    nav_msgs/Path                       latched: the path being followed
``current_goal``            cyborg_msgs/GoalWithHeading         latched: the goal driven to, or
                                                                an empty name
``map_geometry``            cyborg_msgs/MapGeometry             latched: the map for displays, at
                                                                the start and after each switch
``footprint``               geometry_msgs/PolygonStamped        latched: the body's outline
``/tf_static``              tf2_msgs/TFMessage                  latched: base_link → laser
``move_to_goal``            cyborg_msgs/action/MoveToGoal       drive to a goal name or a pose
``dock``, ``undock``,       std_srvs/Trigger                    docking; ``stop`` cancels the goal
``stop``
``set_pose``                cyborg_msgs/srv/SetPose             teleport the robot
``cmd_vel`` (subscribed)    geometry_msgs/Twist                 drive by hand, with a deadman
``/initialpose``            geometry_msgs/                      teleport the robot (RViz)
(subscribed)                PoseWithCovarianceStamped
==========================  ==================================  ==================================

plus the navigation services of :mod:`cyborg.nav.services` (goals, distances, make_plan,
load_map_file), answered on the simulator's own map. Sensor topics are published at most
``max_publish_rate`` times per wall-clock second, so a simulation running hundreds of times
faster than real time does not flood the bus; ``/clock`` follows every sensor step.

With several robots on one bus (:mod:`cyborg.sim.fleet`) each has a node of its own under its
namespace; only one of them publishes ``/clock`` (``publishes_clock``) and follows the absolute
``/initialpose`` (``initial_pose``), and each names its frames with a prefix (``frame_prefix``
``robot1/``: ``robot1/base_link`` → ``robot1/laser`` on ``/tf_static``, the scans'
``frame_id`` ``robot1/laser``), as ROS multi-robot setups do, since ``/tf_static`` is one
topic for the whole bus. A robot alone keeps the plain names.
``set_pose``, ``cmd_vel`` and ``/initialpose`` are :class:`~cyborg.sim.manual_node.ManualControl`'s.
"""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from cyborg.bus import Node, ServerGoal
from cyborg.bus.msgs.builtin_interfaces.msg import Time
from cyborg.bus.msgs.cyborg_msgs.action import (
    MoveToGoal,
    MoveToGoal_Feedback,
    MoveToGoal_Goal,
    MoveToGoal_Result,
)
from cyborg.bus.msgs.cyborg_msgs.msg import BatteryStatus, BumperState, GoalWithHeading
from cyborg.bus.msgs.geometry_msgs.msg import (
    Point32,
    Polygon,
    PolygonStamped,
    PoseWithCovariance,
    Quaternion,
    Transform,
    TransformStamped,
    Twist,
    TwistWithCovariance,
    Vector3,
)
from cyborg.bus.msgs.nav_msgs.msg import Odometry
from cyborg.bus.msgs.rosgraph_msgs.msg import Clock
from cyborg.bus.msgs.sensor_msgs.msg import LaserScan
from cyborg.bus.msgs.std_msgs.msg import Header, String
from cyborg.bus.msgs.std_srvs.srv import Trigger, Trigger_Request, Trigger_Response
from cyborg.bus.msgs.tf2_msgs.msg import TFMessage
from cyborg.interfaces import robot
from cyborg.interfaces.robot import (
    BASE_FRAME,
    LASER_FRAME,
    MAP_FRAME,
    DockState,
    MoveOutcome,
    PathState,
)
from cyborg.nav.arnl_map import ArnlMap
from cyborg.nav.geometry import Pose2D
from cyborg.nav.map_message import MapPublisher
from cyborg.nav.planner import Planner
from cyborg.nav.services import NavigationMap, NavigationServices
from cyborg.sim.loop import RobotLoop
from cyborg.sim.manual_node import ManualControl
from cyborg.sim.simulator import Simulator, Target

SUCCEEDED, FAILED, CANCELED, NO_PATH = (int(MoveOutcome.SUCCEEDED), int(MoveOutcome.FAILED),
                                       int(MoveOutcome.CANCELED), int(MoveOutcome.NO_PATH))
"""MoveToGoal's result outcomes (see :class:`cyborg.interfaces.robot.MoveOutcome`)."""
FEEDBACK_PERIOD = 0.25
"""Simulated seconds between move_to_goal feedback messages (and checks of the goal)."""


class SimulatorNode:
    """Publishes a running simulation and serves its actions and services.

    ``clock`` gives wall-clock seconds (for the ``cmd_vel`` deadman); ``initial_pose``: whether
    to follow ``/initialpose`` (see :class:`~cyborg.sim.manual_node.ManualControl`);
    ``publishes_clock``: whether to publish ``/clock``; ``frame_prefix`` goes before the
    robot's frame names (``robot1/`` makes ``robot1/base_link``; not before ``map``).
    """

    def __init__(self, node: Node, loop: RobotLoop, max_publish_rate: float = 30.0, *,
                 clock: Callable[[], float] = time.monotonic, initial_pose: bool = True,
                 publishes_clock: bool = True, frame_prefix: str = "") -> None:
        self.node, self.loop, self.sim = node, loop, loop.simulator
        self.base_frame = frame_prefix + BASE_FRAME
        self.laser_frame = frame_prefix + LASER_FRAME
        self._min_period = 1.0 / max_publish_rate
        self._published_at = 0.0
        self._last_state: tuple[Any, ...] = ()
        self._battery_at = -math.inf
        self._path_shown: object = None
        self._goal_generation = 0
        self._preempted_by = ""
        self._goal_shown: Target | None = None
        self._stepped = threading.Condition()  # notified after every sensor step
        self._newest_goal = 0
        self._active_goal: ServerGoal[MoveToGoal_Goal, MoveToGoal_Feedback] | None = None
        self._feedback_at = -math.inf
        self.clock = robot.CLOCK.publisher(node) if publishes_clock else None
        self.pose = robot.POSE.publisher(node)
        self.odom = robot.ODOM.publisher(node)
        self.scan = robot.SCAN.publisher(node)
        self.bumpers = robot.BUMPER_STATE.publisher(node)
        self.battery = robot.BATTERY_STATUS.publisher(node)
        self.path_state = robot.PATH_STATE.publisher(node)
        self.path = robot.PATH.publisher(node)
        self.current_goal = robot.CURRENT_GOAL.publisher(node)
        self.current_goal.publish(self._goal_message(None))
        self.maps = NavigationMap(self.sim.map, self.sim.planner)
        self.maps.listeners.append(self._map_changed)
        self.services = NavigationServices(node, self.maps, lambda: self.sim.pose)
        self.map_geometry = MapPublisher(node, self.maps, self._stamp)
        self.footprint = robot.FOOTPRINT.publisher(node)
        self.footprint.publish(self._footprint())
        self.tf_static = robot.TF_STATIC.publisher(node)
        self.tf_static.publish(self._transforms())
        # stop, dock, undock, set_pose and cmd_vel are handled on a thread of their own: a slow
        # plan, a closest-goal search or a goal being accepted never delays the stop button
        motion = node.callback_thread("motion")
        robot.DOCK.server(node, self._dock, callbacks=motion)
        robot.UNDOCK.server(node, self._undock, callbacks=motion)
        robot.STOP.server(node, self._stop, callbacks=motion)
        self.manual = ManualControl(node, loop, self._preempt, motion, clock=clock,
                                    initial_pose=initial_pose)
        robot.MOVE_TO_GOAL.server(node, self._move)
        loop.on_sensor.append(self._publish)

    # ------------------------------------------------------------------ publishing
    def _stamp(self) -> Time:
        # Whole nanoseconds first: int() and round() of the parts apart turned 2.9999999999999996
        # into 2 s + 0 ns, one second back, which /clock followers take for a jump.
        sec, nanosec = divmod(round(self.sim.time * 1e9), 1_000_000_000)
        return Time(sec=sec, nanosec=nanosec)

    def _header(self, frame: str) -> Header:
        return Header(stamp=self._stamp(), frame_id=frame)

    def _publish(self, sim: Simulator) -> None:
        if self.node.destroyed:
            # the node went first (its context closed, or a stop whose join timed out): the
            # simulation ends here quietly instead of failing on a withdrawn publisher
            self.loop.stop()
            return
        try:
            self._publish_step(sim)
        except RuntimeError:
            if not self.node.destroyed:  # destroyed while publishing: the same quiet end
                raise
            self.loop.stop()

    def _publish_step(self, sim: Simulator) -> None:
        self._feedback(sim)
        with self._stepped:
            self._stepped.notify_all()
        if self.clock is not None:
            self.clock.publish(Clock(clock=self._stamp()))
        if sim.time - self._battery_at >= 1.0:
            self._battery_at = sim.time
            self._publish_battery(sim)
        state = (sim.base.bumpers.front, sim.base.bumpers.rear, sim.navigator.state)
        if state != self._last_state:
            self._last_state = state
            self.bumpers.publish(BumperState(
                header=self._header(self.base_frame), front_bumpers=np.array([state[0]]),
                rear_bumpers=np.array([state[1]])))
            self.path_state.publish(String(data=state[2].value))
        goal = sim.current_goal
        if goal is not self._goal_shown:
            self._goal_shown = goal
            self.current_goal.publish(self._goal_message(goal))
        follower = sim.navigator.follower
        if follower is not None and follower.path is not self._path_shown:
            self._path_shown = follower.path
            self.path.publish(follower.path.to_message(stamp=self._stamp()))
        now = time.monotonic()
        if now - self._published_at < self._min_period:
            return
        self._published_at = now
        pose = sim.pose
        self.pose.publish(pose.to_message())
        self.odom.publish(self._odometry(sim))
        self.scan.publish(self._scan(sim))

    def _publish_battery(self, sim: Simulator) -> None:
        battery = sim.battery
        self.battery.publish(BatteryStatus(
            header=self._header(self.base_frame), charging_state=int(battery.state),
            charge_percent=battery.charge_percent, voltage=battery.voltage,
            charging=battery.charging, dock_state=sim.docking.state.value))

    def _odometry(self, sim: Simulator) -> Odometry:
        # zero covariances: unknown, as nav_msgs/Odometry says of zeros
        pose = PoseWithCovariance(pose=sim.pose.to_pose().to_message(),
                                  covariance=np.zeros(36))
        twist = Twist(linear=Vector3(x=float(sim.base.speed), y=0.0, z=0.0),
                      angular=Vector3(x=0.0, y=0.0, z=float(sim.base.turn_rate)))
        return Odometry(header=self._header(MAP_FRAME), child_frame_id=self.base_frame,
                        pose=pose,
                        twist=TwistWithCovariance(twist=twist, covariance=np.zeros(36)))

    def _scan(self, sim: Simulator) -> LaserScan:
        spec = sim.laser.spec
        return LaserScan(
            header=self._header(self.laser_frame), angle_min=spec.angle_min,
            angle_max=spec.angle_min + spec.angle_increment * (spec.beams - 1),
            angle_increment=spec.angle_increment, time_increment=0.0,
            scan_time=1.0 / sim.settings.sensor_rate, range_min=spec.range_min,
            range_max=spec.range_max, ranges=sim.ranges.astype(np.float32),
            intensities=np.zeros(0, np.float32))

    @staticmethod
    def _goal_message(goal: Target | None) -> GoalWithHeading:
        """``current_goal``: a pose goal is named by its coordinates; none has an empty name."""
        if goal is None:
            return GoalWithHeading(name="", comment="", position=Pose2D().to_message(),
                                   has_heading=False)
        pose = goal.pose
        return GoalWithHeading(name=goal.name or f"({pose.x:.2f}, {pose.y:.2f})",
                               comment=goal.comment, position=pose.to_message(),
                               has_heading=goal.use_heading)

    def _footprint(self) -> PolygonStamped:
        """The body's outline in its own frame (it never changes)."""
        corners = [Point32(x=float(x), y=float(y), z=0.0)
                   for x, y in self.sim.base.footprint.polygon()]
        return PolygonStamped(header=self._header(self.base_frame),
                              polygon=Polygon(points=corners))

    def _transforms(self) -> TFMessage:
        """Where the laser sits on the robot: ``mount_x`` ahead of the axle, facing forward."""
        mount = TransformStamped(
            header=self._header(self.base_frame), child_frame_id=self.laser_frame,
            transform=Transform(
                translation=Vector3(x=float(self.sim.laser.spec.mount_x), y=0.0, z=0.0),
                rotation=Quaternion(x=0.0, y=0.0, z=0.0, w=1.0)))
        return TFMessage(transforms=[mount])

    def _map_changed(self, arnl_map: ArnlMap, planner: Planner) -> None:
        """Switch the simulation to a new map (``load_map_file``, on the loading thread).

        The grids are built before the simulation's lock is taken, so ``stop`` and the
        simulation wait only for the swap.
        """
        prepared = self.sim.prepare_map(arnl_map, planner=planner)
        with self.loop.lock:
            self.sim.install_map(prepared)

    # ------------------------------------------------------------------ services
    @staticmethod
    def _trigger(success: bool, message: str) -> Trigger_Response:
        return Trigger.Response(success=success, message=message)

    def _preempt(self, reason: str) -> None:
        """End the move_to_goal goal under way, if any, with ``reason`` (lock held)."""
        self._goal_generation += 1
        self._preempted_by = reason

    def _dock(self, _request: Trigger_Request) -> Trigger_Response:
        with self.loop.lock:
            self._preempt("preempted by docking (dock)")
            ok = self.sim.dock()
            return self._trigger(ok, "docking" if ok else self.sim.docking.message)

    def _undock(self, _request: Trigger_Request) -> Trigger_Response:
        with self.loop.lock:
            ok = self.sim.undock()
            return self._trigger(ok, "undocking" if ok else
                                 f"not docked ({self.sim.docking.state.value})")

    def _stop(self, _request: Trigger_Request) -> Trigger_Response:
        with self.loop.lock:
            self._preempt("stopped (stop)")
            self.sim.cancel()
            self.sim.end_teleop()
        return self._trigger(True, "stopped")

    # ------------------------------------------------------------------ move_to_goal
    def _move(self, goal: ServerGoal[MoveToGoal_Goal, MoveToGoal_Feedback]) -> MoveToGoal_Result:
        """Run one move_to_goal goal: start it, then wait for its end.

        Feedback is sent from the simulation's own thread (see :meth:`_feedback`), every
        ``FEEDBACK_PERIOD`` simulated seconds, so that however fast the simulation runs and
        however busy the machine is, a client sees progress in step with simulated time.
        Goals take over in the order they were accepted: a goal whose thread starts after a
        newer one's is preempted at once.
        """
        request = goal.request
        result = MoveToGoal.Result
        with self.loop.lock:
            if goal.cancel_requested:
                goal.canceled()
                return result(outcome=CANCELED, message="cancelled before it started")
            if goal.sequence < self._newest_goal:
                goal.abort()
                return result(outcome=FAILED, message="preempted by a newer goal")
            self._newest_goal = goal.sequence
            self._preempt("preempted by another goal")
            generation = self._goal_generation
            try:
                target = request.goal_name or Pose2D.from_message(request.pose)
                # a named goal's kind decides unless the request asks for the heading
                heading = True if request.use_heading else (None if request.goal_name else False)
                plan = self.sim.go_to(target, heading)
            except KeyError as exc:
                goal.abort()
                return result(outcome=NO_PATH, message=str(exc).strip("'\""))
            if not plan.found:
                goal.abort()
                return result(outcome=NO_PATH, message=f"{plan.code}: {plan.reason}")
            self._active_goal, self._feedback_at = goal, -math.inf
            self._feedback(self.sim)
        try:
            while True:
                with self._stepped:
                    self._stepped.wait(0.05)
                with self.loop.lock:
                    state, message = self.sim.navigator.state, self.sim.navigator.message
                    busy = self.sim.docking.state is not DockState.UNDOCKED
                    if generation != self._goal_generation:
                        goal.abort()
                        return result(outcome=FAILED, message=self._preempted_by)
                    if goal.cancel_requested:
                        self.sim.cancel()
                        goal.canceled()
                        return result(outcome=CANCELED, message="cancelled")
                if not busy and state is PathState.REACHED_GOAL:
                    return result(outcome=SUCCEEDED, message="reached the goal")
                if not busy and state.finished and state is not PathState.NOT_INITIALIZED:
                    goal.abort()
                    return result(outcome=FAILED, message=f"{state.value}: {message}")
                if self.loop.error is not None or not self.loop.running:
                    goal.abort()
                    return result(outcome=FAILED, message="the simulation stopped")
        finally:
            with self.loop.lock:
                if self._active_goal is goal:
                    self._active_goal = None

    def _feedback(self, sim: Simulator) -> None:
        """Send the active goal's feedback when it is due (simulation thread, lock held)."""
        goal = self._active_goal
        if goal is None or sim.time < self._feedback_at + FEEDBACK_PERIOD:
            return
        self._feedback_at = sim.time
        goal.publish_feedback(MoveToGoal.Feedback(
            current_pose=sim.pose.to_message(),
            distance_remaining=min(sim.navigator.remaining, 1e9)))
