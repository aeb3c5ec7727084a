"""A node: a named participant of the bus, visible to ``cyborg node list`` and ``ros2 node list``.

    from cyborg.bus import Context, Node, Qos

    from cyborg.bus.msgs.std_msgs.msg import String

    with Context() as context:
        node = Node("talker", namespace="/robot1", context=context)
        chatter = node.create_publisher("chatter", String)   # Publisher[String]
        chatter.publish(String(data="hello"))

Message, service and action types are given as classes (and :class:`~cyborg.bus.typed.
ServiceType`, :class:`~cyborg.bus.typed.ActionType`) imported from :mod:`cyborg.bus.msgs`, which
makes what is created generic in them for mypy; or by name (``"std_msgs/msg/String"``), typed
``Any``.

Each node runs its callbacks (subscriptions, services, timers) one at a time on its own thread;
a subscription's callback runs there even for a message published in this process, unless the
subscription opted in with ``inline=True``. A service that must never wait behind them gets a
thread of its own with ``create_service(..., callbacks=node.callback_thread("name"))``.
Nodes of one process normally share one :class:`~cyborg.bus.context.Context`; without one, a
node uses the process's default context (see :func:`default_context`).
"""

from __future__ import annotations

import re
import threading
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, Literal, Protocol, TypeVar, overload

from cyborg.bus.context import Context
from cyborg.bus.executor import CallbackThread
from cyborg.bus.message_types import MessageTypes
from cyborg.bus.parameters import Parameters
from cyborg.bus.raw import RawMessage, RawPublisher, RawSubscription
from cyborg.bus.services import Responder, ServiceClient, ServiceServer
from cyborg.bus.topics import Publisher, Subscription
from cyborg.bus.typed import ActionType, ServiceType
from cyborg.bus.wire import Attachment, Qos, node_token

if TYPE_CHECKING:
    from cyborg.bus.action_client import ActionClient
    from cyborg.bus.actions import ActionServer, ServerGoal

_NAME = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")
_NAMESPACE = re.compile(r"^(/[A-Za-z][A-Za-z0-9_]*)*/?$")


class _Entity(Protocol):
    """What a node keeps of each endpoint it made: whether it is gone, and how to end it."""

    @property
    def closed(self) -> bool: ...

    def destroy(self) -> None: ...


_E = TypeVar("_E", bound=_Entity)
_M = TypeVar("_M")
_Req = TypeVar("_Req")
_Resp = TypeVar("_Resp")
_G = TypeVar("_G")
_R = TypeVar("_R")
_F = TypeVar("_F")

_default: Context | None = None
_default_lock = threading.Lock()


def default_context() -> Context:
    """The process-wide context, opened on first use from the environment, closed at exit."""
    global _default
    with _default_lock:
        if _default is None or _default.closed:
            _default = Context()
        return _default


class Node:
    """A ROS-style node: publishers, subscriptions, services, actions, parameters, timers.

    ``name`` and ``namespace`` make its full name, ``/ns/name`` (ValueError if either is not a
    ROS name); ``context`` defaults to :func:`default_context`; ``parameters`` overrides the
    defaults of parameters the node declares later (:class:`~cyborg.bus.parameters.Parameters`).
    """

    def __init__(self, name: str, namespace: str = "/", *, context: Context | None = None,
                 parameters: dict[str, Any] | None = None) -> None:
        if not _NAME.match(name):
            raise ValueError(f"node name {name!r}: letters, digits and _ only, starting "
                             "with a letter")
        namespace = "/" + namespace.strip("/") if namespace.strip("/") else "/"
        if not _NAMESPACE.match(namespace):
            raise ValueError(f"namespace {namespace!r}: /-separated names of letters, digits, _")
        self.context = context if context is not None else default_context()
        self.name, self.namespace = name, namespace
        self.fq_name = f"{namespace.rstrip('/')}/{name}"
        self.id = self.context.next_id()
        self.callbacks = CallbackThread(self.fq_name)
        self._callback_threads: list[CallbackThread] = []
        self._entities: list[_Entity] = []
        self._kept_after_prune = 16
        self._timers: list[Timer] = []
        self._destroyed = False
        self.token_key = node_token(self.context.domain, self.context.zid, self.id,
                                    namespace, name)
        self._token = self.context.session.liveliness().declare_token(self.token_key)
        self.context.register_node(self)
        self.parameters = Parameters(self, overrides=parameters or {})

    @property
    def destroyed(self) -> bool:
        """True once :meth:`destroy` has run (or begun)."""
        return self._destroyed

    @property
    def types(self) -> MessageTypes:
        """The message types of the node's context."""
        return self.context.types

    # ------------------------------------------------------------------ topics
    @overload
    def create_publisher(self, topic: str, message_type: type[_M],
                         qos: Qos | None = None) -> Publisher[_M]: ...
    @overload
    def create_publisher(self, topic: str, message_type: str,
                         qos: Qos | None = None) -> Publisher[Any]: ...

    def create_publisher(self, topic: str, message_type: type[Any] | str,
                         qos: Qos | None = None) -> Publisher[Any]:
        """A publisher of ``message_type``: a class from :mod:`cyborg.bus.msgs`, or a type name.

        ``Qos.latched()`` keeps the last message for late subscribers; the default QoS is
        reliable with a depth of 10.
        """
        return self._keep(Publisher, topic, self.types.type_name(message_type),
                          qos or Qos(depth=10))

    @overload
    def create_subscription(self, topic: str, message_type: type[_M],
                            callback: Callable[[_M], object], qos: Qos | None = None, *,
                            with_info: Literal[False] = False,
                            inline: bool = False) -> Subscription[_M]: ...
    @overload
    def create_subscription(self, topic: str, message_type: type[_M],
                            callback: Callable[[_M, Attachment | None], object],
                            qos: Qos | None = None, *, with_info: Literal[True],
                            inline: bool = False) -> Subscription[_M]: ...
    @overload
    def create_subscription(self, topic: str, message_type: str,
                            callback: Callable[..., object], qos: Qos | None = None, *,
                            with_info: bool = False, inline: bool = False) -> Subscription[Any]: ...

    def create_subscription(self, topic: str, message_type: type[Any] | str,
                            callback: Callable[..., object], qos: Qos | None = None, *,
                            with_info: bool = False, inline: bool = False) -> Subscription[Any]:
        """Call ``callback(message)`` for each message; use ``Qos.latched()`` for latched topics.

        The callback runs on this node's thread, also for messages published in this process.
        ``with_info=True``: ``callback(message, info)``, ``info`` being the sample's
        :class:`~cyborg.bus.wire.Attachment` (claimed publisher GID, sequence, timestamp) or None.
        ``inline=True`` lets an in-process message be handed to the callback on the publisher's
        thread when this node is idle (see :class:`~cyborg.bus.topics.Subscription`).
        """
        return self._keep(Subscription, topic, self.types.type_name(message_type), callback,
                          qos or Qos(depth=10), with_info=with_info, inline=inline)

    def create_raw_subscription(self, topic: str, type_name: str,
                                callback: Callable[[RawMessage], object],
                                qos: Qos | None = None, *,
                                batched: bool = False) -> RawSubscription:
        """Call ``callback(RawMessage)`` with each message's CDR bytes, never decoded.

        For recorders: the bytes are the message as it travelled (see :mod:`cyborg.bus.raw`);
        ``type_name`` (a known type) makes the key, ``qos`` as for :meth:`create_subscription`.
        ``batched``: messages wait until the node calls the subscription's ``drain()``.
        """
        return self._keep(RawSubscription, topic, type_name, callback, qos or Qos(depth=10),
                          batched=batched)

    def create_raw_publisher(self, topic: str, type_name: str,
                             qos: Qos | None = None) -> RawPublisher:
        """A publisher of CDR bytes as they are (``publish_raw``), for players.

        See :mod:`cyborg.bus.raw`; ``type_name`` (a known type) makes the key, ``qos`` as for
        :meth:`create_publisher`.
        """
        return self._keep(RawPublisher, topic, type_name, qos or Qos(depth=10))

    # ------------------------------------------------------------------ services
    @overload
    def create_service(self, name: str, service_type: ServiceType[_Req, _Resp],
                       handler: Callable[[_Req], _Resp], *, deferred: Literal[False] = False,
                       callbacks: CallbackThread | None = None) -> ServiceServer[_Req, _Resp]: ...
    @overload
    def create_service(self, name: str, service_type: ServiceType[_Req, _Resp],
                       handler: Callable[[_Req, Responder[_Resp]], object], *,
                       deferred: Literal[True],
                       callbacks: CallbackThread | None = None) -> ServiceServer[_Req, _Resp]: ...
    @overload
    def create_service(self, name: str, service_type: str, handler: Callable[..., Any], *,
                       deferred: bool = False,
                       callbacks: CallbackThread | None = None) -> ServiceServer[Any, Any]: ...

    def create_service(self, name: str, service_type: ServiceType[Any, Any] | str,
                       handler: Callable[..., Any], *, deferred: bool = False,
                       callbacks: CallbackThread | None = None) -> ServiceServer[Any, Any]:
        """Serve ``handler(request) -> response`` (see :class:`ServiceServer`).

        ``callbacks`` (from :meth:`callback_thread`): run the handler there instead of on the
        node's thread, so that the node's other callbacks never delay it.
        """
        server: ServiceServer[Any, Any] = self._keep(
            ServiceServer, name, self.types.service_name(service_type), handler,
            deferred=deferred)
        if callbacks is not None:
            self.callbacks.route(server, callbacks)
        return server

    def callback_thread(self, name: str) -> CallbackThread:
        """Another thread for some of this node's callbacks; it stops with the node.

        It is like a ROS 2 callback group with an executor of its own; ``name`` tells it apart
        in thread names and logs. Raises RuntimeError once the node is destroyed.
        """
        if self._destroyed:
            raise RuntimeError(f"node {self.fq_name} was destroyed")
        thread = CallbackThread(f"{self.fq_name}[{name}]")
        self._callback_threads.append(thread)
        return thread

    @overload
    def create_client(self, name: str,
                      service_type: ServiceType[_Req, _Resp]) -> ServiceClient[_Req, _Resp]: ...
    @overload
    def create_client(self, name: str, service_type: str) -> ServiceClient[Any, Any]: ...

    def create_client(self, name: str,
                      service_type: ServiceType[Any, Any] | str) -> ServiceClient[Any, Any]:
        """A client of a service (a :class:`~cyborg.bus.typed.ServiceType` or a type name)."""
        return self._keep(ServiceClient, name, self.types.service_name(service_type))

    # ------------------------------------------------------------------ actions
    @overload
    def create_action_server(
            self, name: str, action_type: ActionType[_G, _R, _F],
            execute: Callable[[ServerGoal[_G, _F]], _R | None], *,
            accept: Callable[[_G], bool] | None = None,
            cancel: Callable[[ServerGoal[_G, _F]], bool] | None = None,
            max_goals: int | None = None) -> ActionServer[_G, _R, _F]: ...
    @overload
    def create_action_server(
            self, name: str, action_type: str, execute: Callable[[ServerGoal[Any, Any]], Any], *,
            accept: Callable[[Any], bool] | None = None,
            cancel: Callable[[ServerGoal[Any, Any]], bool] | None = None,
            max_goals: int | None = None) -> ActionServer[Any, Any, Any]: ...

    def create_action_server(
            self, name: str, action_type: ActionType[Any, Any, Any] | str,
            execute: Callable[[ServerGoal[Any, Any]], Any], *,
            accept: Callable[[Any], bool] | None = None,
            cancel: Callable[[ServerGoal[Any, Any]], bool] | None = None,
            max_goals: int | None = None) -> ActionServer[Any, Any, Any]:
        """Serve an action (see :class:`cyborg.bus.actions.ActionServer`)."""
        from cyborg.bus.actions import MAX_GOALS, ActionServer
        return self._keep(ActionServer, name, self.types.action_name(action_type), execute,
                          accept=accept, cancel=cancel,
                          max_goals=MAX_GOALS if max_goals is None else max_goals)

    @overload
    def create_action_client(self, name: str, action_type: ActionType[_G, _R, _F]
                             ) -> ActionClient[_G, _R, _F]: ...
    @overload
    def create_action_client(self, name: str, action_type: str) -> ActionClient[Any, Any, Any]: ...

    def create_action_client(self, name: str, action_type: ActionType[Any, Any, Any] | str
                             ) -> ActionClient[Any, Any, Any]:
        """A client of an action (see :class:`cyborg.bus.action_client.ActionClient`)."""
        from cyborg.bus.action_client import ActionClient
        return self._keep(ActionClient, name, self.types.action_name(action_type))

    # ------------------------------------------------------------------ timers
    def create_timer(self, period: float, callback: Callable[[], object]) -> Timer:
        """Call ``callback()`` every ``period`` seconds (wall time) on the node's thread."""
        if self._destroyed:
            raise RuntimeError(f"node {self.fq_name} was destroyed")
        timer = Timer(self, period, callback)
        self._timers = [t for t in self._timers if not t.cancelled]
        self._timers.append(timer)
        return timer

    # ------------------------------------------------------------------ lifetime
    def _keep(self, factory: Callable[..., _E], *args: Any, **options: Any) -> _E:
        if self._destroyed or self.context.closed:
            raise RuntimeError(f"node {self.fq_name} was destroyed")
        entity = factory(self, *args, **options)
        self._entities.append(entity)
        if len(self._entities) >= 2 * self._kept_after_prune:
            # entities destroyed one by one (a viewer's subscriptions, a reload's clients) are
            # forgotten here, so a node that lives for days does not hold them all
            self._entities = [e for e in self._entities if not e.closed]
            self._kept_after_prune = max(16, len(self._entities))
        return entity

    def destroy(self) -> None:
        """Withdraw everything the node declared and stop its thread. Safe to call twice."""
        if self._destroyed:
            return
        self._destroyed = True
        for timer in self._timers:
            timer.cancel()
        for entity in reversed(self._entities):
            entity.destroy()
        if not self.context.closed:
            self._token.undeclare()
        self.callbacks.close()
        for thread in self._callback_threads:
            thread.close()
        self.context.forget_node(self)

    def __enter__(self) -> Node:
        return self

    def __exit__(self, *exc: object) -> None:
        self.destroy()


class Timer:
    """A periodic callback on the node's thread; ticks that would pile up are skipped.

    Made by :meth:`Node.create_timer`: ``callback()`` every ``period`` seconds of wall time
    (ValueError unless positive), timed on a thread of its own.
    """

    def __init__(self, node: Node, period: float, callback: Callable[[], object]) -> None:
        if period <= 0:
            raise ValueError(f"timer period must be positive, not {period}")
        self.period, self.callback = period, callback
        self._node = node
        self._stop = threading.Event()
        self._pending = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True,
                                        name=f"cyborg-timer{node.fq_name}")
        self._thread.start()

    def _run(self) -> None:
        while not self._stop.wait(self.period):
            if not self._pending.is_set():
                self._pending.set()
                self._node.callbacks.submit(self._fire)

    def _fire(self) -> None:
        self._pending.clear()
        if not self._stop.is_set():
            self.callback()

    @property
    def cancelled(self) -> bool:
        """Whether :meth:`cancel` has been called."""
        return self._stop.is_set()

    def cancel(self) -> None:
        """Stop the timer: no call starts after this returns. Safe to call twice."""
        self._stop.set()
        if threading.current_thread() is not self._thread:
            self._thread.join(1.0)
