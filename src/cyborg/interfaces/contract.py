"""The descriptors a contract is written with: :class:`Topic`, :class:`Service`, :class:`Action`.

A descriptor is the part of an endpoint that both sides must agree on — its name, its type and,
for a topic, whether it is latched — and nothing else: it holds no connection and can be
shared freely (the classes are frozen). It makes the endpoint on a node for either side::

    POSE = Topic("pose", "geometry_msgs/msg/Pose2D")
    POSE.publisher(node)                                  # the server side, in node's namespace
    POSE.subscription(node, on_pose, namespace="/cyborg") # a client, under a robot's namespace

Names are relative, as in ROS: without ``namespace`` they resolve in the node's own namespace,
with it they resolve under that one (:func:`resolve`). A name that starts with ``/`` (such as
``/clock``) is absolute and stays as it is.

Constants the message definitions declare (``uint8 DISABLE=1`` in ControlNode.srv) are taken
from the generated message classes (``ControlNode_Request.DISABLE`` from
:mod:`cyborg.bus.msgs`, which ``python3 -m cyborg.bus.codegen --check`` keeps equal to the
.msg, .srv and .action files), so an enum in a contract never retypes them.

The bus names types by string today (``type_name``); when it takes message classes, each
descriptor gains its class here and the call sites stay as they are.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

from cyborg.bus.wire import Qos, fully_qualified

if TYPE_CHECKING:
    from cyborg.bus import Node
    from cyborg.bus.services import ServiceClient, ServiceServer
    from cyborg.bus.topics import Publisher, Subscription

DEFAULT_DEPTH = 10
"""History depth of a topic that names none (the bus's default for publishers and
subscriptions); a latched topic keeps 1 unless told otherwise."""


def resolve(namespace: str, name: str) -> str:
    """The full name of ``name`` under ``namespace``, as the bus resolves it:
    ``("/cyborg", "pose")`` → ``/cyborg/pose``, ``("/", "pose")`` → ``/pose``; an absolute
    ``name`` (``/clock``) is returned as it is."""
    return fully_qualified(namespace, name)


def _at(name: str, namespace: str | None) -> str:
    return name if namespace is None else resolve(namespace, name)


@dataclass(frozen=True)
class Topic:
    """A topic: its name (relative or absolute), message type and QoS."""

    name: str
    type_name: str
    """``package/msg/Name``."""
    latched: bool = False
    """Transient-local: a subscriber that comes late still gets the last message."""
    depth: int | None = None
    """History depth; None: 1 when latched, else :data:`DEFAULT_DEPTH`."""

    @property
    def qos(self) -> Qos:
        """The QoS both sides use (a subscriber may ask for a deeper queue)."""
        if self.latched:
            return Qos.latched(self.depth if self.depth is not None else 1)
        return Qos(depth=self.depth if self.depth is not None else DEFAULT_DEPTH)

    def full_name(self, namespace: str) -> str:
        """The topic's name under ``namespace`` (see :func:`resolve`)."""
        return resolve(namespace, self.name)

    def remapped(self, name: str) -> Topic:
        """The same topic under another name, as a ROS remapping gives it (e.g. a camera
        topic chosen by the user)."""
        return replace(self, name=name)

    def publisher(self, node: Node, namespace: str | None = None) -> Publisher:
        return node.create_publisher(_at(self.name, namespace), self.type_name, self.qos)

    def subscription(self, node: Node, callback: Callable[..., object],
                     namespace: str | None = None, *, qos: Qos | None = None) -> Subscription:
        """Subscribe with the topic's QoS, or ``qos`` (same durability, another depth)."""
        return node.create_subscription(_at(self.name, namespace), self.type_name, callback,
                                        qos or self.qos)


@dataclass(frozen=True)
class Service:
    """A service: its name (relative or absolute) and service type."""

    name: str
    type_name: str
    """``package/srv/Name``."""

    @property
    def request_type(self) -> str:
        return f"{self.type_name}_Request"

    @property
    def response_type(self) -> str:
        return f"{self.type_name}_Response"

    def full_name(self, namespace: str) -> str:
        return resolve(namespace, self.name)

    def server(self, node: Node, handler: Callable[..., Any], namespace: str | None = None,
               **options: Any) -> ServiceServer:
        """Serve ``handler``; ``options`` as :meth:`cyborg.bus.Node.create_service` takes them
        (``deferred``, ``callbacks``)."""
        return node.create_service(_at(self.name, namespace), self.type_name, handler, **options)

    def client(self, node: Node, namespace: str | None = None) -> ServiceClient:
        return node.create_client(_at(self.name, namespace), self.type_name)


@dataclass(frozen=True)
class Action:
    """An action: its name (relative or absolute) and action type."""

    name: str
    type_name: str
    """``package/action/Name``."""

    @property
    def goal_type(self) -> str:
        return f"{self.type_name}_Goal"

    @property
    def result_type(self) -> str:
        return f"{self.type_name}_Result"

    @property
    def feedback_type(self) -> str:
        return f"{self.type_name}_Feedback"

    def full_name(self, namespace: str) -> str:
        return resolve(namespace, self.name)

    def server(self, node: Node, execute: Callable[[Any], Any], namespace: str | None = None,
               **options: Any) -> Any:
        """Serve the action (see :class:`cyborg.bus.actions.ActionServer` for ``options``)."""
        return node.create_action_server(_at(self.name, namespace), self.type_name, execute,
                                         **options)

    def client(self, node: Node, namespace: str | None = None) -> Any:
        return node.create_action_client(_at(self.name, namespace), self.type_name)
