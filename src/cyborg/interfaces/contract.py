"""The descriptors a contract is written with: :class:`Topic`, :class:`Service`, :class:`Action`.

A descriptor is the part of an endpoint that both sides must agree on — its name, its type and,
for a topic, whether it is latched — and nothing else: it holds no connection and can be
shared freely (the classes are frozen). It makes the endpoint on a node for either side::

    from cyborg.bus.msgs.geometry_msgs.msg import Pose2D

    POSE = Topic("pose", Pose2D)                          # a Topic[Pose2D]
    POSE.publisher(node)                                  # a Publisher[Pose2D], in node's namespace
    POSE.subscription(node, on_pose, namespace="/cyborg") # on_pose(message: Pose2D), a client

A descriptor carries the type as the class (or :class:`~cyborg.bus.typed.ServiceType`,
:class:`~cyborg.bus.typed.ActionType`) imported from :mod:`cyborg.bus.msgs`, so it is generic
in it (``Topic[Pose2D]``, ``Service[Trigger_Request, Trigger_Response]``) and the endpoints it
makes are typed too: strict mypy checks the messages published, the callbacks' and handlers'
fields and the results on both sides. ``type_name`` still gives the name
(``geometry_msgs/msg/Pose2D``), e.g. to compare with what the bus graph says.

Names are relative, as in ROS: without ``namespace`` they resolve in the node's own namespace,
with it they resolve under that one (:func:`resolve`). A name that starts with ``/`` (such as
``/clock``) is absolute and stays as it is.

Constants the message definitions declare (``uint8 DISABLE=1`` in ControlNode.srv) are taken
from the generated message classes (``ControlNode_Request.DISABLE`` from
:mod:`cyborg.bus.msgs`, which ``python3 -m cyborg.bus.codegen --check`` keeps equal to the
.msg, .srv and .action files), so an enum in a contract never retypes them.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any, Generic, Literal, overload

from cyborg.bus.typed import (
    ActionType,
    FeedbackT,
    GoalT,
    MessageT,
    RequestT,
    ResponseT,
    ResultT,
    ServiceType,
    message_type_name,
)
from cyborg.bus.wire import Qos, fully_qualified

if TYPE_CHECKING:
    from cyborg.bus import Node
    from cyborg.bus.action_client import ActionClient
    from cyborg.bus.actions import ActionServer, ServerGoal
    from cyborg.bus.executor import CallbackThread
    from cyborg.bus.services import Responder, ServiceClient, ServiceServer
    from cyborg.bus.topics import Publisher, Subscription

DEFAULT_DEPTH = 10
"""History depth of a topic that names none (the bus's default for publishers and
subscriptions); a latched topic keeps 1 unless told otherwise."""


def resolve(namespace: str, name: str) -> str:
    """The full name of ``name`` under ``namespace``, as the bus resolves it.

    ``("/cyborg", "pose")`` → ``/cyborg/pose``, ``("/", "pose")`` → ``/pose``; an absolute
    ``name`` (``/clock``) is returned as it is.
    """
    return fully_qualified(namespace, name)


def _at(name: str, namespace: str | None) -> str:
    return name if namespace is None else resolve(namespace, name)


@dataclass(frozen=True)
class Topic(Generic[MessageT]):
    """A topic: its name (relative or absolute), message class and QoS."""

    name: str
    message_type: type[MessageT]
    """The message class, from :mod:`cyborg.bus.msgs` (``Pose2D``)."""
    latched: bool = False
    """Transient-local: a subscriber that comes late still gets the last message."""
    depth: int | None = None
    """History depth; None: 1 when latched, else :data:`DEFAULT_DEPTH`."""

    @property
    def type_name(self) -> str:
        """The message type's name, ``package/msg/Name``, as the bus graph shows it."""
        return message_type_name(self.message_type)

    @property
    def qos(self) -> Qos:
        """The QoS both sides use (a subscriber may ask for a deeper queue)."""
        if self.latched:
            return Qos.latched(self.depth if self.depth is not None else 1)
        return Qos(depth=self.depth if self.depth is not None else DEFAULT_DEPTH)

    def full_name(self, namespace: str) -> str:
        """The topic's name under ``namespace`` (see :func:`resolve`)."""
        return resolve(namespace, self.name)

    def remapped(self, name: str) -> Topic[MessageT]:
        """The same topic under another name, as a ROS remapping gives it.

        A camera topic chosen by the user, for example; type and QoS stay the contract's.
        """
        return replace(self, name=name)

    def publisher(self, node: Node, namespace: str | None = None) -> Publisher[MessageT]:
        """The publishing side, on ``node``, with the topic's QoS.

        Without ``namespace`` the name resolves in the node's namespace, with it under that one.
        """
        return node.create_publisher(_at(self.name, namespace), self.message_type, self.qos)

    def subscription(self, node: Node, callback: Callable[[MessageT], object],
                     namespace: str | None = None, *,
                     qos: Qos | None = None) -> Subscription[MessageT]:
        """The subscribing side: ``callback(message)`` runs on ``node``'s thread per message.

        The topic's QoS is used, or ``qos`` (same durability, another depth); ``namespace`` as
        for :meth:`publisher`.
        """
        return node.create_subscription(_at(self.name, namespace), self.message_type, callback,
                                        qos or self.qos)


@dataclass(frozen=True)
class Service(Generic[RequestT, ResponseT]):
    """A service: its name (relative or absolute) and service type."""

    name: str
    service_type: ServiceType[RequestT, ResponseT]
    """The service type, from :mod:`cyborg.bus.msgs` (``Trigger``, with ``Trigger.Request``
    and ``Trigger.Response``)."""

    @property
    def type_name(self) -> str:
        """The service type's name, ``package/srv/Name``, as the bus graph shows it."""
        return self.service_type.name

    @property
    def request_type(self) -> str:
        """The request's type name, ``package/srv/Name_Request``."""
        return message_type_name(self.service_type.Request)

    @property
    def response_type(self) -> str:
        """The response's type name, ``package/srv/Name_Response``."""
        return message_type_name(self.service_type.Response)

    def full_name(self, namespace: str) -> str:
        """The service's name under ``namespace`` (see :func:`resolve`)."""
        return resolve(namespace, self.name)

    @overload
    def server(self, node: Node, handler: Callable[[RequestT], ResponseT],
               namespace: str | None = None, *, deferred: Literal[False] = False,
               callbacks: CallbackThread | None = None) -> ServiceServer[RequestT, ResponseT]:
        ...

    @overload
    def server(self, node: Node,
               handler: Callable[[RequestT, Responder[ResponseT]], object],
               namespace: str | None = None, *, deferred: Literal[True],
               callbacks: CallbackThread | None = None) -> ServiceServer[RequestT, ResponseT]:
        ...

    def server(self, node: Node, handler: Callable[..., Any], namespace: str | None = None, *,
               deferred: bool = False,
               callbacks: CallbackThread | None = None) -> ServiceServer[RequestT, ResponseT]:
        """The serving side, on ``node``: ``handler(request)`` returns the response.

        With ``deferred=True`` the handler is ``handler(request, responder)`` and answers
        through the responder when it is ready; ``callbacks`` (a thread from
        :meth:`cyborg.bus.Node.callback_thread`) runs it there instead of on the node's thread.
        As :meth:`cyborg.bus.Node.create_service` takes them; ``namespace`` as for
        :meth:`Topic.publisher`.
        """
        name = _at(self.name, namespace)
        if deferred:
            return node.create_service(name, self.service_type, handler, deferred=True,
                                       callbacks=callbacks)
        return node.create_service(name, self.service_type, handler, callbacks=callbacks)

    def client(self, node: Node, namespace: str | None = None
               ) -> ServiceClient[RequestT, ResponseT]:
        """The calling side, on ``node`` (``namespace`` as for :meth:`Topic.publisher`)."""
        return node.create_client(_at(self.name, namespace), self.service_type)


@dataclass(frozen=True)
class Action(Generic[GoalT, ResultT, FeedbackT]):
    """An action: its name (relative or absolute) and action type."""

    name: str
    action_type: ActionType[GoalT, ResultT, FeedbackT]
    """The action type, from :mod:`cyborg.bus.msgs` (``MoveToGoal``, with ``MoveToGoal.Goal``,
    ``.Result`` and ``.Feedback``)."""

    @property
    def type_name(self) -> str:
        """The action type's name, ``package/action/Name``."""
        return self.action_type.name

    @property
    def goal_type(self) -> str:
        """The goal's type name, ``package/action/Name_Goal``."""
        return message_type_name(self.action_type.Goal)

    @property
    def result_type(self) -> str:
        """The result's type name, ``package/action/Name_Result``."""
        return message_type_name(self.action_type.Result)

    @property
    def feedback_type(self) -> str:
        """The feedback's type name, ``package/action/Name_Feedback``."""
        return message_type_name(self.action_type.Feedback)

    def full_name(self, namespace: str) -> str:
        """The action's name under ``namespace`` (see :func:`resolve`)."""
        return resolve(namespace, self.name)

    def server(self, node: Node,
               execute: Callable[[ServerGoal[GoalT, FeedbackT]], ResultT | None],
               namespace: str | None = None, *,
               accept: Callable[[GoalT], bool] | None = None,
               cancel: Callable[[ServerGoal[GoalT, FeedbackT]], bool] | None = None,
               max_goals: int | None = None) -> ActionServer[GoalT, ResultT, FeedbackT]:
        """The serving side, on ``node``: ``execute(goal)`` runs each goal on its own thread.

        ``accept``, ``cancel`` and ``max_goals`` as :class:`cyborg.bus.actions.ActionServer`
        takes them; ``namespace`` as for :meth:`Topic.publisher`.
        """
        return node.create_action_server(_at(self.name, namespace), self.action_type, execute,
                                         accept=accept, cancel=cancel, max_goals=max_goals)

    def client(self, node: Node, namespace: str | None = None
               ) -> ActionClient[GoalT, ResultT, FeedbackT]:
        """The client side, on ``node`` (``namespace`` as for :meth:`Topic.publisher`)."""
        return node.create_action_client(_at(self.name, namespace), self.action_type)
