"""Acting on the simulated robot by hand, on the bus: ``set_pose``, ``/initialpose``, ``cmd_vel``.

:class:`ManualControl` is part of :class:`~cyborg.sim.node.SimulatorNode`. It serves
``set_pose`` and follows ``/initialpose`` (RViz's and Foxglove's pose estimate), both of which
teleport the robot (:meth:`cyborg.sim.simulator.Simulator.set_pose`), and follows ``cmd_vel``,
which drives it by hand (:meth:`cyborg.sim.simulator.Simulator.teleop`). Each ends the
``move_to_goal`` goal under way (outcome FAILED, the message saying what took over).

The deadman. Driving by hand stops :data:`~cyborg.interfaces.robot.TELEOP_TIMEOUT` (0.5 s)
after the last ``cmd_vel`` command, counted on the **wall clock**, not in simulated time. The
commands come from a person (keys, a joystick, MobileEyes' ratioDrive) at the pace of the wall
clock, say 10 a second; under ``cyborg up`` simulated time runs 30 times faster, so 0.5
simulated seconds would pass in 17 ms, between two commands, and the robot would stutter. What
the deadman guards against, a sender gone quiet (a closed page, a lost network), is a matter
of wall-clock time too. The price: in a fast simulation the robot covers more simulated ground
before the deadman stops it (at 30 times, up to 15 simulated seconds of driving), within the
speed limit and the motion check as always. The deadman is looked at after every sensor step
of the simulation.
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Callable

from cyborg.bus import Node
from cyborg.bus.executor import CallbackThread
from cyborg.bus.msgs.cyborg_msgs.srv import SetPose, SetPose_Request, SetPose_Response
from cyborg.bus.msgs.geometry_msgs.msg import PoseWithCovarianceStamped, Twist
from cyborg.interfaces import robot
from cyborg.interfaces.robot import MAP_FRAME, TELEOP_TIMEOUT
from cyborg.nav.geometry import Pose, Pose2D
from cyborg.sim.loop import RobotLoop
from cyborg.sim.simulator import Simulator

log = logging.getLogger("cyborg.sim")

WARNING_PERIOD = 5.0
"""Wall-clock seconds between warnings about bad commands (the rest are counted)."""


class ManualControl:
    """Serves ``set_pose`` and follows ``cmd_vel`` and ``/initialpose`` on ``node``.

    ``preempt(reason)`` ends the ``move_to_goal`` goal under way, if any, with ``reason``; it
    is called with the simulation's lock held. The endpoints' callbacks run on ``callbacks``
    (a thread of the node's, so a slow plan never delays a stop). ``clock`` gives wall-clock
    seconds for the deadman (see the module docstring). With ``initial_pose`` false,
    ``/initialpose`` is not followed: it is absolute, so with several robots on one bus only
    one of them should follow it.
    """

    def __init__(self, node: Node, loop: RobotLoop, preempt: Callable[[str], None],
                 callbacks: CallbackThread, *, clock: Callable[[], float] = time.monotonic,
                 initial_pose: bool = True, timeout: float = TELEOP_TIMEOUT) -> None:
        self.node, self.loop, self.sim = node, loop, loop.simulator
        self.timeout = timeout
        self._preempt, self._clock = preempt, clock
        self._driven_at: float | None = None  # wall clock of the last command, while driving
        self._warned: dict[str, tuple[float, int]] = {}  # per kind: when, how many since
        robot.SET_POSE.server(node, self._set_pose, callbacks=callbacks)
        drive = robot.CMD_VEL.subscription(node, self._drive)
        node.callbacks.route(drive, callbacks)
        if initial_pose:
            estimate = robot.INITIAL_POSE.subscription(node, self._initial_pose)
            node.callbacks.route(estimate, callbacks)
        loop.on_sensor.append(self._watch)

    # ------------------------------------------------------------------ set_pose
    def relocate(self, pose: Pose2D, by: str) -> tuple[bool, str]:
        """Put the robot at ``pose`` (``by`` names who asked): whether it was, and a sentence."""
        with self.loop.lock:
            problem = self.sim.set_pose(pose)
            if problem is None:
                self._preempt(f"the robot was moved ({by})")
                self._driven_at = None
            now = self.sim.pose
        if problem is not None:
            return False, problem
        return True, (f"the robot stands at ({now.x:.2f}, {now.y:.2f}) heading "
                      f"{math.degrees(now.theta):.0f}°")

    def _set_pose(self, request: SetPose_Request) -> SetPose_Response:
        success, message = self.relocate(Pose2D.from_message(request.pose), "set_pose")
        return SetPose.Response(success=success, message=message)

    def _initial_pose(self, message: PoseWithCovarianceStamped) -> None:
        name = robot.INITIAL_POSE.full_name(self.node.namespace)
        frame = message.header.frame_id.lstrip("/")
        if frame not in ("", MAP_FRAME):
            self._warn("frame", f"{name}: a pose in frame {frame!r} ignored: only "
                                f"{MAP_FRAME!r} is known")
            return
        success, text = self.relocate(Pose.from_message(message.pose.pose).to_pose2d(), name)
        if success:
            log.info("%s: %s", name, text)
        else:
            self._warn("initialpose", f"{name} refused: {text}")

    # ------------------------------------------------------------------ cmd_vel
    def _drive(self, twist: Twist) -> None:
        linear, angular = twist.linear, twist.angular
        values = (linear.x, linear.y, linear.z, angular.x, angular.y, angular.z)
        if not all(math.isfinite(value) for value in values):
            self._warn("cmd_vel", f"{robot.CMD_VEL.full_name(self.node.namespace)}: a twist "
                       f"that is not finite ignored (linear {linear.x}, {linear.y}, "
                       f"{linear.z}; angular {angular.x}, {angular.y}, {angular.z})")
            return
        with self.loop.lock:
            self._preempt("the robot is driven by hand (cmd_vel)")
            self.sim.teleop(float(linear.x), float(angular.z))
            self._driven_at = self._clock()

    def _watch(self, sim: Simulator) -> None:
        """The deadman (the simulation's thread, lock held): stop when the commands stopped."""
        if self._driven_at is None:
            return
        command = sim.teleop_command
        if command is None:  # a goal took over
            self._driven_at = None
        elif self._clock() - self._driven_at > self.timeout:
            sim.end_teleop()
            self._driven_at = None
            if command != (0.0, 0.0):
                log.info("%s: no command for %g s: stopping",
                         robot.CMD_VEL.full_name(self.node.namespace), self.timeout)

    def _warn(self, kind: str, text: str) -> None:
        """Log ``text`` as a warning, at most once per :data:`WARNING_PERIOD` for each ``kind``."""
        now = self._clock()
        warned_at, since = self._warned.get(kind, (-math.inf, 0))
        if now - warned_at < WARNING_PERIOD:
            self._warned[kind] = (warned_at, since + 1)
            return
        self._warned[kind] = (now, 0)
        log.warning("%s%s", text, f" (and {since} more like it since the last warning)"
                    if since else "")
