"""Actions: long-running goals with feedback, a result and cancel, in ROS 2's conventions.

An action ``/robot/move_to_goal`` is three services and two topics under ``_action``:
``send_goal``, ``cancel_goal`` (action_msgs/srv/CancelGoal) and ``get_result`` services, the
``feedback`` topic and the latched ``status`` topic (action_msgs/msg/GoalStatusArray).

Server side, ``execute(goal)`` runs on a thread of its own per goal and returns the result; it
reports progress with ``goal.publish_feedback(...)`` and should watch ``goal.cancel_requested``
(then stop and call ``goal.canceled()``). Returning ends the goal as SUCCEEDED, unless it called
``goal.abort()`` or ``goal.canceled()``; raising ends it as ABORTED.

Client side (:mod:`cyborg.bus.action_client`)::

    from cyborg.bus.msgs.cyborg_msgs.action import MoveToGoal

    client = node.create_action_client("move_to_goal", MoveToGoal)
    goal = client.send_goal(MoveToGoal.Goal(goal_name="kitchen", ...), feedback=print)
    goal.cancel()                      # later, e.g. when a behaviour is halted
    status, result = goal.result(timeout=60)

Made from an :class:`~cyborg.bus.typed.ActionType`, servers, clients and goals are generic in
its goal, result and feedback classes, so mypy checks what ``execute`` reads and returns, the
feedback, and the result a client gets.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable
from enum import IntEnum
from typing import TYPE_CHECKING, Any, Generic

import numpy as np

from cyborg.bus.conversion import new_message
from cyborg.bus.msgs.action_msgs.msg import GoalInfo, GoalStatusArray
from cyborg.bus.msgs.action_msgs.msg import GoalStatus as GoalStatusMessage
from cyborg.bus.msgs.action_msgs.srv import CancelGoal, CancelGoal_Request, CancelGoal_Response
from cyborg.bus.msgs.builtin_interfaces.msg import Time
from cyborg.bus.msgs.unique_identifier_msgs.msg import UUID
from cyborg.bus.services import Responder
from cyborg.bus.typed import FeedbackT, GoalT, ResultT
from cyborg.bus.wire import Qos

if TYPE_CHECKING:
    from cyborg.bus.node import Node

log = logging.getLogger("cyborg.bus")

STATUS_QOS = Qos.latched(depth=1)
KEEP_FINISHED = 100
"""Finished goals whose results can still be fetched."""
MAX_GOALS = 100
"""Goals a server runs at once (each has a thread); more are rejected until some finish."""
MAX_RESULT_WAITERS = 16
"""get_result requests one running goal holds open; more are answered with an error at once."""


class GoalStatus(IntEnum):
    """action_msgs/msg/GoalStatus values."""

    UNKNOWN = 0
    ACCEPTED = 1
    EXECUTING = 2
    CANCELING = 3
    SUCCEEDED = 4
    CANCELED = 5
    ABORTED = 6

    @property
    def terminal(self) -> bool:
        """Whether the goal has ended: SUCCEEDED, CANCELED or ABORTED."""
        return self >= GoalStatus.SUCCEEDED


class ActionError(RuntimeError):
    """A goal was rejected, or the action server could not be reached."""


def stamp(seconds: float | None = None) -> Time:
    """A ``builtin_interfaces/msg/Time`` of ``seconds`` since the epoch (now if None)."""
    now = time.time() if seconds is None else seconds
    return Time(sec=int(now), nanosec=int((now % 1) * 1e9))


def goal_uuid(raw: bytes) -> UUID:
    """A goal id (16 bytes) as a ``unique_identifier_msgs/msg/UUID``."""
    return UUID(uuid=np.frombuffer(raw, dtype=np.uint8).copy())


class ServerGoal(Generic[GoalT, FeedbackT]):
    """One goal on the server: the request, its status, feedback and cancel flag."""

    def __init__(self, server: ActionServer[GoalT, Any, FeedbackT], goal_id: bytes,
                 request: GoalT, sequence: int = 0) -> None:
        self.server, self.id, self.request = server, goal_id, request
        self.sequence = sequence
        """Order of acceptance on this server, from 1: a goal with a higher number came later
        (goal threads may start in any order)."""
        self.status = GoalStatus.ACCEPTED
        self.accepted_at = time.time()
        self._cancel = threading.Event()
        self._ending: GoalStatus | None = None

    @property
    def cancel_requested(self) -> bool:
        """Whether the goal is to stop: a cancel was granted, or the server is being destroyed.

        ``execute`` should watch it, then stop and call :meth:`canceled`.
        """
        return self._cancel.is_set()

    def publish_feedback(self, feedback: FeedbackT) -> None:
        """Send ``feedback`` to the clients following this goal (from any thread)."""
        self.server._feedback(self, feedback)

    def abort(self) -> None:
        """End the goal as ABORTED when ``execute`` returns, whatever it returns."""
        self._ending = GoalStatus.ABORTED

    def canceled(self) -> None:
        """End the goal as CANCELED when ``execute`` returns (after a cancel request)."""
        self._ending = GoalStatus.CANCELED

    def succeed(self) -> None:
        """End the goal as SUCCEEDED when ``execute`` returns, as returning does anyway."""
        self._ending = GoalStatus.SUCCEEDED


class ActionServer(Generic[GoalT, ResultT, FeedbackT]):
    """Accepts goals, runs ``execute(goal) -> result`` for each, answers result requests.

    ``accept(request) -> bool`` may reject goals; ``cancel(goal) -> bool`` may refuse a cancel.

    Goal ids come from clients, so the tables keyed by them are bounded: a goal id the server
    already knows is rejected (as rcl_action does), at most ``max_goals`` goals run at once,
    and at most ``MAX_RESULT_WAITERS`` result requests wait for one goal.
    """

    def __init__(self, node: Node, name: str, action_type: str,
                 execute: Callable[[ServerGoal[GoalT, FeedbackT]], ResultT | None], *,
                 accept: Callable[[GoalT], bool] | None = None,
                 cancel: Callable[[ServerGoal[GoalT, FeedbackT]], bool] | None = None,
                 max_goals: int = MAX_GOALS) -> None:
        types = node.types
        if action_type not in types.actions:
            raise KeyError(f"{name}: unknown action type {action_type!r}")
        self.node, self.types, self.action_type = node, types, action_type
        self.execute, self.accept, self.allow_cancel = execute, accept, cancel
        self.name, self.max_goals = name, max_goals
        self._goals: dict[bytes, ServerGoal[GoalT, FeedbackT]] = {}
        self._results: dict[bytes, tuple[GoalStatus, Any]] = {}
        self._waiting: dict[bytes, list[Responder]] = {}
        self._lock = threading.Lock()
        self._accepted = 0
        self._closed = False
        base = f"{name}/_action/"
        # The parts this action type adds (SendGoal, GetResult, FeedbackMessage) have no
        # class in an ActionType: they are named after the action type, which comes as a name.
        self._send_goal_response = types.message_class(f"{action_type}_SendGoal_Response")
        self._result_class = types.message_class(f"{action_type}_Result")
        self._get_result_response = types.message_class(f"{action_type}_GetResult_Response")
        self._feedback_message = types.message_class(f"{action_type}_FeedbackMessage")
        self._entities: list[Any] = [
            node.create_service(base + "send_goal", f"{action_type}_SendGoal", self._on_goal),
            node.create_service(base + "cancel_goal", CancelGoal, self._on_cancel),
            node.create_service(base + "get_result", f"{action_type}_GetResult",
                                self._on_get_result, deferred=True)]
        self._feedback_pub = node.create_publisher(
            base + "feedback", f"{action_type}_FeedbackMessage")
        self._status_pub = node.create_publisher(base + "status", GoalStatusArray, STATUS_QOS)
        self._publish_status()

    def _on_goal(self, request: Any) -> Any:
        goal_id = bytes(request.goal_id.uuid)
        refusal = self._refusal(goal_id)
        if refusal:
            log.warning("action %s: goal %s rejected: %s", self.name, goal_id.hex(), refusal)
            accepted = False
        else:
            accepted = self.accept(request.goal) if self.accept is not None else True
        response = self._send_goal_response(accepted=bool(accepted), stamp=stamp())
        if accepted:
            with self._lock:
                self._accepted += 1
                goal = ServerGoal(self, goal_id, request.goal, self._accepted)
                self._goals[goal_id] = goal
            self._publish_status()
            threading.Thread(target=self._run, args=(goal,), daemon=True,
                             name=f"cyborg-goal{self.name}").start()
        return response

    def _refusal(self, goal_id: bytes) -> str:
        """Why a goal cannot be taken whatever it asks for; empty if it can."""
        with self._lock:
            if goal_id in self._goals or goal_id in self._results:
                return "its id is already known (a replayed or duplicated request)"
            running = sum(1 for goal in self._goals.values() if not goal.status.terminal)
        if running >= self.max_goals:
            return f"{running} goals are running, the most this server takes ({self.max_goals})"
        return ""

    def _run(self, goal: ServerGoal[GoalT, FeedbackT]) -> None:
        self._set_status(goal, GoalStatus.EXECUTING)
        result: Any
        try:
            result = self.execute(goal)
            status = goal._ending or GoalStatus.SUCCEEDED
        except Exception as exc:
            log.error("action %s: execute raised %s: %s", self.name, type(exc).__name__, exc,
                      exc_info=True)
            result, status = None, GoalStatus.ABORTED
        if not isinstance(result, self._result_class):
            if result is not None:
                log.error("action %s: execute returned %s, not %s_Result", self.name,
                          type(result).__name__, self.action_type)
                status = GoalStatus.ABORTED
            result = new_message(self.types, f"{self.action_type}_Result")
        self._finish(goal, status, result)

    def _finish(self, goal: ServerGoal[GoalT, FeedbackT], status: GoalStatus,
                result: Any) -> None:
        with self._lock:
            self._results[goal.id] = (status, result)
            while len(self._results) > KEEP_FINISHED:
                oldest = next(iter(self._results))
                self._results.pop(oldest)
                self._goals.pop(oldest, None)
            waiting = self._waiting.pop(goal.id, [])
        self._set_status(goal, status)
        for responder in waiting:
            responder.reply(self._result_response(status, result))

    def _result_response(self, status: GoalStatus, result: Any) -> Any:
        return self._get_result_response(status=int(status), result=result)

    def _on_get_result(self, request: Any, responder: Responder) -> None:
        goal_id = bytes(request.goal_id.uuid)
        with self._lock:
            finished = self._results.get(goal_id)
            if finished is None and goal_id in self._goals:
                waiting = self._waiting.setdefault(goal_id, [])
                if len(waiting) < MAX_RESULT_WAITERS:
                    waiting.append(responder)
                    return
                crowded = True
            else:
                crowded = False
        if crowded:
            responder.fail(ActionError(f"{MAX_RESULT_WAITERS} requests are already waiting for "
                                       f"the result of goal {goal_id.hex()}"))
            return
        if finished is None:  # unknown goal: ROS answers UNKNOWN with an empty result
            result_type = f"{self.action_type}_Result"
            responder.reply(self._result_response(GoalStatus.UNKNOWN,
                                                  new_message(self.types, result_type)))
            return
        responder.reply(self._result_response(*finished))

    def _on_cancel(self, request: CancelGoal_Request) -> CancelGoal_Response:
        wanted = bytes(request.goal_info.goal_id.uuid)
        before = request.goal_info.stamp.sec + request.goal_info.stamp.nanosec * 1e-9
        with self._lock:
            candidates = [g for g in self._goals.values() if not g.status.terminal]
        if any(wanted):
            candidates = [g for g in candidates if g.id == wanted]
        elif before:
            candidates = [g for g in candidates if g.accepted_at <= before]
        canceling = [g for g in candidates
                     if self.allow_cancel is None or self.allow_cancel(g)]
        for goal in canceling:
            goal._cancel.set()
            self._set_status(goal, GoalStatus.CANCELING)
        code = 0 if canceling or not candidates else 1
        if any(wanted) and not candidates:
            code = 3 if wanted in self._goals else 2
        return CancelGoal.Response(return_code=code, goals_canceling=[
            GoalInfo(goal_id=goal_uuid(g.id), stamp=stamp(g.accepted_at)) for g in canceling])

    def _feedback(self, goal: ServerGoal[GoalT, FeedbackT], feedback: FeedbackT) -> None:
        if self._closed:
            return
        self._feedback_pub.publish(self._feedback_message(goal_id=goal_uuid(goal.id),
                                                          feedback=feedback))

    def _set_status(self, goal: ServerGoal[GoalT, FeedbackT], status: GoalStatus) -> None:
        if goal.status.terminal:
            return
        goal.status = status
        self._publish_status()

    def _publish_status(self) -> None:
        if self._closed:
            return  # a goal thread finishing after the node was destroyed
        with self._lock:
            goals = list(self._goals.values())
        message = GoalStatusArray(status_list=[
            GoalStatusMessage(goal_info=GoalInfo(goal_id=goal_uuid(g.id),
                                                 stamp=stamp(g.accepted_at)),
                              status=int(g.status)) for g in goals])
        try:
            self._status_pub.publish(message)
        except RuntimeError:
            if not self._closed:
                raise

    @property
    def closed(self) -> bool:
        """Whether the action server was destroyed."""
        return self._closed

    def destroy(self) -> None:
        """Withdraw the action from the bus and ask every running goal to stop.

        Running goals see :attr:`ServerGoal.cancel_requested`; their threads are not waited for.
        """
        with self._lock:
            goals = list(self._goals.values())
            self._closed = True
        for goal in goals:
            goal._cancel.set()
        for entity in (*self._entities, self._feedback_pub, self._status_pub):
            entity.destroy()
