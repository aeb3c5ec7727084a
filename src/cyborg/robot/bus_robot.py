"""The robot over the bus: its ARNL-like interface, as the simulator and the real robot offer it.

Under the robot's namespace (``/cyborg`` by default) it uses the topics ``pose`` and
``battery_status``, the services ``nav/get_available_goals``, ``nav/get_distance_to_goal``,
``nav/get_closest_goal``, ``dock``, ``undock`` and ``stop``, and the ``move_to_goal`` action
(see :mod:`cyborg.interfaces.robot` for the full interface, which the simulator serves); it
publishes its calls for help on ``help`` (:mod:`cyborg.interfaces.help`); and for the
perception nodes it uses the tracker's ``objects``, ``say`` and ``cmd_vel``
(:class:`~cyborg.robot.bus_perception.BusPerception`)::

    robot = BusRobot(Node("bt", "/cyborg"), "/cyborg")
    move = robot.move_to("room1")
    ...
    move.done, move.outcome, move.remaining
"""

from __future__ import annotations

import logging
import math
import threading
from collections.abc import Callable
from concurrent.futures import Future
from typing import Any

from cyborg.bus import ActionError, ClientGoal, Node, ServiceError, new_message
from cyborg.interfaces import robot
from cyborg.interfaces.help import HELP, HelpCall, help_text
from cyborg.nav.geometry import Pose2D
from cyborg.robot.bus_perception import BusPerception
from cyborg.robot.perceiving import SeenObject
from cyborg.robot.protocol import BatteryReading, DockState, Goal, MoveOutcome, RobotError
from cyborg.robot.rate_limited_log import RateLimitedLog

log = logging.getLogger("cyborg.robot")
limited = RateLimitedLog(log)


class BusMove:
    """A move_to_goal goal in progress."""

    def __init__(self, handle: ClientGoal | None, goal: str, error: str = "",
                 path_state: Callable[[], str] = str) -> None:
        self.goal = goal
        self._path_state = path_state
        self._handle = handle
        self._error = error
        self._remaining = math.inf
        self._cancel_sent = False

    def on_feedback(self, feedback: Any) -> None:
        """Keeps the goal's ``distance_remaining`` (m); called on the bus node's thread."""
        self._remaining = float(feedback.distance_remaining)

    @property
    def done(self) -> bool:
        """Whether the goal has ended, or could not be sent at all."""
        return self._handle is None or self._handle.done

    @property
    def outcome(self) -> MoveOutcome | None:
        """How the goal ended; None while it runs, FAILED when its result is out of reach."""
        return self._ended()[0]

    @property
    def message(self) -> str:
        """The result's message, or the error that failed the goal; empty while it runs."""
        return self._ended()[1]

    def _ended(self) -> tuple[MoveOutcome | None, str]:
        """``(outcome, message)``: ``(None, "")`` while the goal runs.

        A goal that could not be sent or whose result could not be fetched counts as FAILED.
        """
        handle = self._handle
        if handle is None:
            return MoveOutcome.FAILED, self._error
        if not handle.done:
            return None, ""
        try:
            _status, result = handle.result(0)
        except (ActionError, ServiceError) as exc:
            return MoveOutcome.FAILED, str(exc)
        try:
            return MoveOutcome(int(result.outcome)), str(result.message)
        except ValueError:
            return MoveOutcome.FAILED, str(result.message)

    @property
    def remaining(self) -> float:
        """Metres left along the planned path, from the last feedback (inf before any)."""
        return self._remaining

    @property
    def waiting(self) -> bool:
        """Whether the robot's path state says it waits for people or objects to make way."""
        return not self.done and self._path_state() == robot.PathState.WAITING_FOR_PATH

    def cancel(self) -> None:
        """Sends a cancel request once, on the bus's call pool; a failure is only logged."""
        handle = self._handle
        if handle is None or handle.done or self._cancel_sent:
            return
        self._cancel_sent = True
        future = handle.client.node.context.calls.submit(handle.cancel)
        future.add_done_callback(self._cancelled)

    def _cancelled(self, future: Future[bool]) -> None:
        error = future.exception()
        if error is not None:  # the robot is gone: every move's cancel fails the same way
            limited.warning("cancel failed", "cancelling the move to %r failed: %s", self.goal,
                            error)


class BusRobot:
    """:class:`~cyborg.robot.protocol.Robot` on the bus, for the robot under ``namespace``."""

    def __init__(self, node: Node, namespace: str = robot.NAMESPACE, *,
                 timeout: float = 5.0) -> None:
        self.node, self.timeout = node, timeout
        prefix = "/" + namespace.strip("/") if namespace.strip("/") else ""
        self.namespace = prefix or "/"
        self._pose: Pose2D | None = None
        self._battery: BatteryReading | None = None
        self._goals: dict[str, Goal] | None = None
        self._lock = threading.Lock()
        robot.POSE.subscription(node, self._on_pose, namespace)
        robot.BATTERY_STATUS.subscription(node, self._on_battery, namespace)
        self._path_state = ""
        robot.PATH_STATE.subscription(node, self._on_path_state, namespace)
        self._clients = {service.name: service.client(node, namespace) for service in (
            robot.AVAILABLE_GOALS, robot.DISTANCE_TO_GOAL, robot.CLOSEST_GOAL, robot.DOCK,
            robot.UNDOCK, robot.STOP)}
        self._action = robot.MOVE_TO_GOAL.client(node, namespace)
        self._help = HELP.publisher(node, namespace)
        self.perception = BusPerception(node, namespace)

    # ------------------------------------------------------------------ state
    def _on_pose(self, message: Any) -> None:
        self._pose = Pose2D.from_message(message)

    def _on_path_state(self, message: Any) -> None:
        self._path_state = str(message.data)

    def _on_battery(self, message: Any) -> None:
        try:
            state = DockState(message.dock_state)
        except ValueError:
            state = DockState.UNKNOWN
        stamp = message.header.stamp
        self._battery = BatteryReading(float(message.charge_percent), bool(message.charging),
                                       state, stamp.sec + stamp.nanosec * 1e-9)

    @property
    def pose(self) -> Pose2D | None:
        """The last ``pose`` message (m, rad); None before the first."""
        return self._pose

    @property
    def battery(self) -> BatteryReading | None:
        """The last ``battery_status`` message; None before the first."""
        return self._battery

    def wait_until_ready(self, timeout: float = 10.0) -> bool:
        """Wait (wall time) until the robot's services answer and its pose is known."""
        client = self._clients[robot.AVAILABLE_GOALS.name]
        if not client.wait_for_service(timeout):
            return False
        return bool(self._action.wait_for_server(timeout))

    # ------------------------------------------------------------------ requests
    def _call(self, name: str, **fields: Any) -> Any:
        client = self._clients[name]
        request = new_message(self.node.types, f"{client.service_type}_Request", fields)
        try:
            return client.call(request, timeout=self.timeout)
        except ServiceError as exc:
            raise RobotError(str(exc)) from exc

    def goals(self, refresh: bool = False) -> dict[str, Goal]:
        """The map's named goals, asked once and cached (``refresh`` asks again).

        Blocks up to ``timeout`` s on the first call; raises RobotError if the robot does not
        answer.
        """
        with self._lock:
            if self._goals is None or refresh:
                reply = self._call(robot.AVAILABLE_GOALS.name)
                self._goals = {goal.name: Goal(goal.name, Pose2D.from_message(goal.position),
                                               goal.comment, bool(goal.has_heading))
                               for goal in reply.goals}
            return dict(self._goals)

    def move_to(self, goal: str) -> BusMove:
        """Sends a move_to_goal goal; raises RobotError if it cannot be sent or is rejected."""
        message = robot.MOVE_TO_GOAL.action_type.Goal(
            goal_name=goal, pose=Pose2D().to_message(), use_heading=False)
        move = BusMove(None, goal, path_state=lambda: self._path_state)
        try:
            move._handle = self._action.send_goal(message, feedback=move.on_feedback,
                                                  timeout=self.timeout)
        except ActionError as exc:
            raise RobotError(f"cannot send the robot to {goal!r}: {exc}") from exc
        return move

    def _trigger(self, name: str) -> tuple[bool, str]:
        reply = self._call(name)
        return bool(reply.success), str(reply.message)

    def dock(self) -> tuple[bool, str]:
        """Calls ``dock``: ``(accepted, message)``; raises RobotError without an answer."""
        return self._trigger(robot.DOCK.name)

    def undock(self) -> tuple[bool, str]:
        """Calls ``undock``: ``(accepted, message)``; raises RobotError without an answer."""
        return self._trigger(robot.UNDOCK.name)

    def stop(self) -> None:
        """Calls ``stop`` and waits for the answer; raises RobotError without one."""
        self._trigger(robot.STOP.name)

    def distance_to(self, goal: Pose2D) -> Future[float]:
        """A future of the planned path's length (m), asked on the call pool; inf without a path."""
        pose = goal.to_pose()
        fields = {"goal": {"position": {"x": pose.position.x, "y": pose.position.y},
                           "orientation": {"z": pose.orientation.z, "w": pose.orientation.w}}}
        return self.node.context.calls.submit(
            lambda: float(self._call(robot.DISTANCE_TO_GOAL.name, **fields).distance))

    def call_for_help(self, reason: str, time: float) -> None:
        """Publishes a call for help on ``help`` (:mod:`cyborg.interfaces.help`).

        The call names the robot's namespace, ``reason``, its last pose and charge, and ``time``.
        """
        pose, battery = self._pose, self._battery
        self._help.publish(help_text(HelpCall(
            self.namespace, reason, None if pose is None else (pose.x, pose.y, pose.theta),
            None if battery is None else battery.charge_percent, time)))

    def closest_goal(self) -> Future[tuple[str, float]]:
        """A future of the closest goal and its path length in m, asked on the call pool."""
        def ask() -> tuple[str, float]:
            reply = self._call(robot.CLOSEST_GOAL.name)
            return str(reply.name), float(reply.distance)
        return self.node.context.calls.submit(ask)

    # ------------------------------------------------------------------ perception
    def objects(self) -> list[SeenObject]:
        """The objects the robot's tracker follows (see :class:`BusPerception`)."""
        return self.perception.objects()

    def say(self, text: str) -> None:
        """Publishes ``text`` for the robot's speech node."""
        self.perception.say(text)

    def drive(self, linear: float, angular: float) -> None:
        """Sends one ``cmd_vel`` command: m/s ahead, rad/s to the left."""
        self.perception.drive(linear, angular)
