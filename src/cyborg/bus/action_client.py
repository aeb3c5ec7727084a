"""The client side of actions: send a goal, follow its feedback and status, get its result.

    from cyborg.bus.msgs.cyborg_msgs.action import MoveToGoal

    client = node.create_action_client("move_to_goal", MoveToGoal)  # ActionClient[...]
    goal = client.send_goal(MoveToGoal.Goal(goal_name="kitchen", ...), feedback=print)
    status, result = goal.result(timeout=60)   # result: MoveToGoal_Result for mypy

The server side, and the conventions both follow, are in :mod:`cyborg.bus.actions`.
"""

from __future__ import annotations

import logging
import time
import uuid
from collections.abc import Callable
from concurrent.futures import Future
from typing import TYPE_CHECKING, Any, Generic

from cyborg.bus.actions import STATUS_QOS, ActionError, GoalStatus, goal_uuid, stamp
from cyborg.bus.msgs.action_msgs.msg import GoalInfo, GoalStatusArray
from cyborg.bus.msgs.action_msgs.srv import CancelGoal
from cyborg.bus.services import ServiceError
from cyborg.bus.typed import FeedbackT, GoalT, ResultT

if TYPE_CHECKING:
    from cyborg.bus.node import Node

log = logging.getLogger("cyborg.bus")

RESULT_WAIT = 30.0
"""Seconds one get_result request waits for a running goal's end before it is asked again.

The server holds the request open until the goal ends; should the request or its answer be
lost on the way, asking again finds the result (the server keeps it), at most this late."""

__all__ = ["ActionClient", "ClientGoal"]


class ClientGoal(Generic[ResultT, FeedbackT]):
    """A goal sent by an :class:`ActionClient`: status, last feedback, result, cancel."""

    def __init__(self, client: ActionClient[Any, ResultT, FeedbackT], goal_id: bytes,
                 accepted: bool, on_feedback: Callable[[FeedbackT], object] | None = None
                 ) -> None:
        self.client, self.id, self.accepted = client, goal_id, accepted
        self.on_feedback = on_feedback
        self.status = GoalStatus.ACCEPTED if accepted else GoalStatus.UNKNOWN
        self.feedback: FeedbackT | None = None
        self._result: Future[tuple[GoalStatus, ResultT]] = Future()
        if accepted:
            client.node.context.calls.submit(self._fetch_result)

    def _fetch_result(self) -> None:
        request = self.client._get_result_request(goal_id=goal_uuid(self.id))
        while not self._result.done():
            try:
                response = self.client._get_result.call(request, timeout=RESULT_WAIT)
            except ServiceError as exc:
                if self.client.closed:
                    self._result.set_exception(ActionError(f"{self.client.name}: client closed"))
                    return
                log.debug("get_result of %s: %s; retrying", self.client.name, exc)
                time.sleep(0.5)
                continue
            self.status = GoalStatus(response.status)
            self._result.set_result((self.status, response.result))

    @property
    def done(self) -> bool:
        """Whether the goal has ended and its result is here (or fetching it failed)."""
        return self._result.done()

    def result(self, timeout: float | None = None) -> tuple[GoalStatus, ResultT]:
        """Block until the goal ends; returns ``(status, result)``."""
        return self._result.result(timeout)

    def add_done_callback(self, callback: Callable[[ClientGoal[ResultT, FeedbackT]], object]
                          ) -> None:
        """Call ``callback(goal)`` once the goal has ended.

        It runs on the thread that fetched the result (a worker of the context's), or at once
        on the calling thread if the goal has ended already.
        """
        self._result.add_done_callback(lambda _future: callback(self))

    def cancel(self, timeout: float = 5.0) -> bool:
        """Ask the server to cancel; True if it agreed (the result then says CANCELED)."""
        return self.client._cancel(self, timeout)


class ActionClient(Generic[GoalT, ResultT, FeedbackT]):
    """Sends goals to an action server and follows them.

    Feedback and status arrive on the node's thread; each goal's result is fetched on a worker
    thread of the context's.
    """

    def __init__(self, node: Node, name: str, action_type: str) -> None:
        types = node.types
        if action_type not in types.actions:
            raise KeyError(f"{name}: unknown action type {action_type!r}")
        self.node, self.types, self.name, self.action_type = node, types, name, action_type
        self._goals: dict[bytes, ClientGoal[ResultT, FeedbackT]] = {}
        # The parts this action type adds (SendGoal, GetResult) have no class in an
        # ActionType: they are named after the action type, which comes as a name.
        self._send_goal_request = types.message_class(f"{action_type}_SendGoal_Request")
        self._get_result_request = types.message_class(f"{action_type}_GetResult_Request")
        self._statuses: dict[bytes, GoalStatus] = {}
        self._closed = False
        base = f"{name}/_action/"
        self._send = node.create_client(base + "send_goal", f"{action_type}_SendGoal")
        self._cancel_client = node.create_client(base + "cancel_goal", CancelGoal)
        self._get_result = node.create_client(base + "get_result", f"{action_type}_GetResult")
        self._feedback_sub = node.create_subscription(
            base + "feedback", f"{action_type}_FeedbackMessage", self._on_feedback)
        self._status_sub = node.create_subscription(
            base + "status", GoalStatusArray, self._on_status, STATUS_QOS)

    def wait_for_server(self, timeout: float = 5.0) -> bool:
        """Whether the action's server is in the graph within ``timeout`` seconds (blocks)."""
        return self._send.wait_for_service(timeout)

    def send_goal(self, goal: GoalT, feedback: Callable[[FeedbackT], object] | None = None,
                  timeout: float = 5.0) -> ClientGoal[ResultT, FeedbackT]:
        """Send a goal; raises :class:`ActionError` if the server rejects it or is absent."""
        goal_id = uuid.uuid4().bytes
        request = self._send_goal_request(goal_id=goal_uuid(goal_id), goal=goal)
        try:
            response = self._send.call(request, timeout)
        except ServiceError as exc:
            raise ActionError(f"action {self.name}: {exc}") from exc
        if not response.accepted:
            raise ActionError(f"action {self.name}: the server rejected the goal")
        handle = ClientGoal(self, goal_id, True, feedback)
        handle.status = self._statuses.get(goal_id, handle.status)  # status may come first
        self._goals[goal_id] = handle
        return handle

    def _cancel(self, goal: ClientGoal[ResultT, FeedbackT], timeout: float) -> bool:
        info = GoalInfo(goal_id=goal_uuid(goal.id), stamp=stamp(0.0))
        response = self._cancel_client.call(CancelGoal.Request(goal_info=info), timeout)
        return int(response.return_code) == 0 and bool(response.goals_canceling)

    def _on_feedback(self, message: Any) -> None:
        goal = self._goals.get(bytes(message.goal_id.uuid))
        if goal is None:
            return
        goal.feedback = message.feedback
        if goal.on_feedback is not None:
            goal.on_feedback(message.feedback)

    def _on_status(self, message: GoalStatusArray) -> None:
        self._statuses = {bytes(entry.goal_info.goal_id.uuid): GoalStatus(entry.status)
                          for entry in message.status_list}
        for goal_id, status in self._statuses.items():
            goal = self._goals.get(goal_id)
            if goal is not None and not goal.done:
                goal.status = status

    @property
    def closed(self) -> bool:
        """Whether the action client was destroyed."""
        return self._closed

    def destroy(self) -> None:
        """Withdraw the client's service clients and subscriptions from the bus."""
        self._closed = True
        for entity in (self._send, self._cancel_client, self._get_result, self._feedback_sub,
                       self._status_sub):
            entity.destroy()
