"""Typed handles: message classes, services and actions as Python types that mypy follows.

A publisher or a subscription made with a message *class* is generic in it, so strict mypy
checks every field name and field type where a message is built, published or read::

    from cyborg.bus.msgs.std_msgs.msg import String

    chatter = node.create_publisher("chatter", String)     # Publisher[String]
    chatter.publish(String(data="hello"))                   # String(dat="hello"): mypy error
    node.create_subscription("chatter", String, lambda message: print(message.data))

A service or an action has no class of its own, so :class:`ServiceType` and :class:`ActionType`
name it and carry the classes of its parts. :mod:`cyborg.bus.msgs` has one for every bundled
interface, next to the message classes::

    from cyborg.bus.msgs.std_srvs.srv import SetBool

    client = node.create_client("enable", SetBool)  # ServiceClient[SetBool_Request, ...]
    client.call(SetBool.Request(data=True)).success

Classes are imported once, at the top of a module, never looked up by name at each use. The
type-name strings (``"std_msgs/msg/String"``) are still accepted everywhere, for type names
only known at run time (the command line); what they give is typed ``Any``.

The type variables have defaults (PEP 696), so ``Publisher`` alone in an annotation means
``Publisher[Any]``, as before these classes were generic.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Generic

from typing_extensions import TypeVar

MessageT = TypeVar("MessageT", default=Any)
"""A message class: ``Publisher[MessageT]``, ``Subscription[MessageT]``."""
RequestT = TypeVar("RequestT", default=Any)
ResponseT = TypeVar("ResponseT", default=Any)
GoalT = TypeVar("GoalT", default=Any)
ResultT = TypeVar("ResultT", default=Any)
FeedbackT = TypeVar("FeedbackT", default=Any)

__all__ = ["ActionType", "FeedbackT", "GoalT", "MessageT", "RequestT", "ResponseT", "ResultT",
           "ServiceType", "action_type_name", "message_type_name", "service_type_name"]


@dataclass(frozen=True)
class ServiceType(Generic[RequestT, ResponseT]):
    """A service type: its name and its request and response classes.

    The name is like ``std_srvs/srv/SetBool``; the classes are as rclpy's ``SetBool.Request``.
    Pass it where a service type name goes.
    """

    name: str
    Request: type[RequestT]
    Response: type[ResponseT]


@dataclass(frozen=True)
class ActionType(Generic[GoalT, ResultT, FeedbackT]):
    """An action type: its name and its goal, result and feedback classes.

    The name is like ``cyborg_msgs/action/MoveToGoal``. Pass it where an action type name goes.
    """

    name: str
    Goal: type[GoalT]
    Result: type[ResultT]
    Feedback: type[FeedbackT]


def message_type_name(message_type: type[Any] | str) -> str:
    """``std_msgs/msg/String`` for that name or for its class (from ``__msgtype__``).

    Raises TypeError for a class that is not a message class.
    """
    if isinstance(message_type, str):
        return message_type
    name = getattr(message_type, "__msgtype__", None)
    if not isinstance(name, str):
        raise TypeError(f"{message_type!r} is not a message class (it has no __msgtype__); "
                        "import message classes from cyborg.bus.msgs")
    return name


def service_type_name(service_type: ServiceType[Any, Any] | str) -> str:
    """The name of a service type given by name or as a :class:`ServiceType`."""
    if isinstance(service_type, ServiceType):
        return service_type.name
    if isinstance(service_type, str):
        return service_type
    raise TypeError(f"{service_type!r} is not a service type: pass a ServiceType "
                    "(from cyborg.bus.msgs) or a name such as 'std_srvs/srv/SetBool'")


def action_type_name(action_type: ActionType[Any, Any, Any] | str) -> str:
    """The name of an action type given by name or as an :class:`ActionType`."""
    if isinstance(action_type, ActionType):
        return action_type.name
    if isinstance(action_type, str):
        return action_type
    raise TypeError(f"{action_type!r} is not an action type: pass an ActionType "
                    "(from cyborg.bus.msgs) or a name such as 'cyborg_msgs/action/MoveToGoal'")
