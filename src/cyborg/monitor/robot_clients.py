"""The monitor's bus clients for one robot: what a page's map actions call on the bus.

A :class:`RobotClients` is made on the monitor's node, under the robot's namespace, when a
page first acts on that robot (:mod:`cyborg.monitor.robot_commands`), with the descriptors of
:mod:`cyborg.interfaces.robot`: the ``move_to_goal`` action client, the ``stop``, ``dock``,
``undock``, ``set_pose`` and ``nav/get_available_goals`` service clients and a ``cmd_vel``
publisher. These are the calls a person makes from MobileEyes or RViz's Nav2 panel, made
through the same contracts the tree's :class:`~cyborg.robot.bus_robot.BusRobot` uses.

Service calls and sending a goal block (up to :data:`CALL_TIMEOUT` seconds): call them from a
worker thread. :meth:`RobotClients.drive` only publishes. A goal's end is awaited on the event
loop with :func:`wait_for_end` and read with :func:`goal_end`, which names MoveToGoal's outcome
as the pages see it (:data:`OUTCOME_NAMES`).
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import math
from dataclasses import dataclass

from cyborg.bus import ActionError, ClientGoal, Node, ServiceError
from cyborg.bus.msgs.cyborg_msgs.action import MoveToGoal_Feedback, MoveToGoal_Result
from cyborg.bus.msgs.cyborg_msgs.srv import AvailableGoals, SetPose
from cyborg.bus.msgs.geometry_msgs.msg import Pose2D, Twist, Vector3
from cyborg.bus.msgs.std_srvs.srv import Trigger
from cyborg.interfaces import robot
from cyborg.interfaces.robot import TELEOP_MAX_SPEED, TELEOP_MAX_TURN_RATE, MoveOutcome

log = logging.getLogger("cyborg.monitor")

CALL_TIMEOUT = 5.0
"""Seconds a service call or a goal's acceptance may take before it counts as unanswered."""
OUTCOME_NAMES = {MoveOutcome.SUCCEEDED: "reached", MoveOutcome.FAILED: "failed",
                 MoveOutcome.CANCELED: "canceled", MoveOutcome.NO_PATH: "no_path"}
"""How a move ended, as ``robot_result`` and ``tour`` messages name it."""

MoveGoal = ClientGoal[MoveToGoal_Result, MoveToGoal_Feedback]
"""A ``move_to_goal`` goal the monitor sent, as the bus follows it."""


class RobotCallError(RuntimeError):
    """The robot did not answer a call, or refused a goal; the message says which and why."""


@dataclass(frozen=True)
class GoalEnd:
    """How a goal ended: an outcome of :data:`OUTCOME_NAMES` and the robot's message."""

    outcome: str
    message: str


def goal_end(goal: MoveGoal) -> GoalEnd:
    """The end of a goal that is done; a result that could not be fetched counts as failed."""
    try:
        _status, result = goal.result(0)
    except (ActionError, ServiceError, TimeoutError) as exc:
        return GoalEnd("failed", f"no result from the robot: {exc}")
    try:
        outcome = OUTCOME_NAMES[MoveOutcome(int(result.outcome))]
    except ValueError:
        outcome = "failed"
    return GoalEnd(outcome, str(result.message))


async def wait_for_end(goal: MoveGoal) -> GoalEnd:
    """Waits on the event loop, without a thread of its own, until ``goal`` ends; how it did."""
    loop = asyncio.get_running_loop()
    done: asyncio.Future[None] = loop.create_future()

    def settle() -> None:
        if not done.done():
            done.set_result(None)

    def ended(_goal: object) -> None:  # on the thread that fetched the result
        with contextlib.suppress(RuntimeError):  # the loop closed: nobody waits any more
            loop.call_soon_threadsafe(settle)

    goal.add_done_callback(ended)
    await done
    return goal_end(goal)


def cancel_later(goal: MoveGoal) -> None:
    """Asks the robot to cancel ``goal``, on the bus's call pool; a failure is only logged."""
    def cancel() -> None:
        try:
            goal.cancel()
        except Exception as exc:  # the robot is gone: its goal is over anyway
            log.info("monitor: cancelling a goal failed: %s", exc)

    goal.client.node.context.calls.submit(cancel)


def clamp_drive(vx: float, wz: float) -> tuple[float, float]:
    """``(vx, wz)`` within the robot's limits for driving by hand (m/s, rad/s)."""
    return (max(-TELEOP_MAX_SPEED, min(TELEOP_MAX_SPEED, vx)),
            max(-TELEOP_MAX_TURN_RATE, min(TELEOP_MAX_TURN_RATE, wz)))


class RobotClients:
    """The bus clients for the robot under ``namespace``, on ``node``; see the module docstring."""

    def __init__(self, node: Node, namespace: str, *, timeout: float = CALL_TIMEOUT) -> None:
        self.namespace, self.timeout = namespace, timeout
        self._triggers = {service.name: service.client(node, namespace)
                          for service in (robot.STOP, robot.DOCK, robot.UNDOCK)}
        self._set_pose = robot.SET_POSE.client(node, namespace)
        self._goals = robot.AVAILABLE_GOALS.client(node, namespace)
        self._action = robot.MOVE_TO_GOAL.client(node, namespace)
        self._cmd_vel = robot.CMD_VEL.publisher(node, namespace)

    def _name(self, service: str) -> str:
        return f"{self.namespace.rstrip('/')}/{service}"

    def trigger(self, service: str) -> tuple[bool, str]:
        """Calls ``stop``, ``dock`` or ``undock``: ``(success, message)``; blocks.

        :class:`RobotCallError` when the robot does not answer.
        """
        client = self._triggers[service]
        try:
            reply = client.call(Trigger.Request(), timeout=self.timeout)
        except ServiceError as exc:
            raise RobotCallError(f"{self._name(service)}: {exc}") from exc
        return bool(reply.success), str(reply.message)

    def set_pose(self, x: float, y: float, theta: float) -> tuple[bool, str]:
        """Calls ``set_pose``: ``(success, message)``, the robot's refusal when it refuses."""
        request = SetPose.Request(pose=Pose2D(x=x, y=y, theta=theta))
        try:
            reply = self._set_pose.call(request, timeout=self.timeout)
        except ServiceError as exc:
            raise RobotCallError(f"{self._name('set_pose')}: {exc}") from exc
        return bool(reply.success), str(reply.message)

    def goal_names(self) -> list[str]:
        """The names of the goals (and docks) of the robot's map, asked of the robot."""
        try:
            reply = self._goals.call(AvailableGoals.Request(), timeout=self.timeout)
        except ServiceError as exc:
            raise RobotCallError(f"{self._name(robot.AVAILABLE_GOALS.name)}: {exc}") from exc
        return [str(goal.name) for goal in reply.goals]

    def send_goal(self, *, name: str = "", pose: tuple[float, float, float] | None = None,
                  use_heading: bool = False) -> MoveGoal:
        """Sends a ``move_to_goal`` goal: the goal ``name``, else ``pose``; blocks until accepted.

        ``use_heading``: turn to the pose's heading on arrival (a named goal's own kind decides
        when false). :class:`RobotCallError` when the robot is absent or rejects it.
        """
        x, y, theta = pose if pose is not None else (0.0, 0.0, 0.0)
        goal = robot.MOVE_TO_GOAL.action_type.Goal(
            goal_name=name, pose=Pose2D(x=x, y=y, theta=theta), use_heading=use_heading)
        try:
            return self._action.send_goal(goal, timeout=self.timeout)
        except ActionError as exc:
            raise RobotCallError(str(exc)) from exc

    def drive(self, vx: float, wz: float) -> tuple[float, float]:
        """Publishes one ``cmd_vel`` within the limits; returns what was sent (m/s, rad/s)."""
        vx, wz = clamp_drive(vx, wz)
        if not (math.isfinite(vx) and math.isfinite(wz)):
            raise ValueError("a drive command is two finite numbers")
        self._cmd_vel.publish(Twist(linear=Vector3(x=vx, y=0.0, z=0.0),
                                    angular=Vector3(x=0.0, y=0.0, z=wz)))
        return vx, wz

    def destroy(self) -> None:
        """Withdraws the clients and the publisher from the bus."""
        for client in self._triggers.values():
            client.destroy()
        for entity in (self._set_pose, self._goals, self._action, self._cmd_vel):
            entity.destroy()
