"""Messaging for cyborg's programs, on Zenoh and wire-compatible with ROS 2 (rmw_zenoh).

* :class:`Context` — one Zenoh session per process; :class:`BusConfig` says how it connects;
* :class:`Node` — publishers and subscriptions (latched too), services, actions, parameters,
  timers (:mod:`cyborg.bus.node`);
* ROS 2 message, service and action types with CDR and RIHS01 type hashes
  (:class:`MessageTypes`), as classes to import from :mod:`cyborg.bus.msgs` (publishers,
  subscriptions, services and actions made from them are generic in them:
  :mod:`cyborg.bus.typed`), and rmw_zenoh's keys, tokens, QoS strings, GIDs and attachments
  (:mod:`cyborg.bus.wire`);
* the ROS graph from liveliness tokens (:mod:`cyborg.bus.graph`).

This package imports nothing else of cyborg.
"""

from cyborg.bus.action_client import ActionClient, ClientGoal
from cyborg.bus.actions import ActionError, ActionServer, GoalStatus, ServerGoal
from cyborg.bus.clock import SimClock
from cyborg.bus.config import BusConfig, BusConfigError
from cyborg.bus.context import Context
from cyborg.bus.conversion import MessageValueError, new_message, to_plain
from cyborg.bus.message_types import BUNDLED_INTERFACES, InterfaceError, MessageTypes
from cyborg.bus.node import Node, default_context
from cyborg.bus.services import (
    Responder,
    ServiceClient,
    ServiceError,
    ServiceServer,
    ServiceTimeoutError,
)
from cyborg.bus.topics import Publisher, Subscription
from cyborg.bus.typed import ActionType, ServiceType
from cyborg.bus.wire import Durability, History, Qos, Reliability

__all__ = ["BUNDLED_INTERFACES", "ActionClient", "ActionError", "ActionServer", "ActionType",
           "BusConfig", "BusConfigError", "ClientGoal", "Context", "Durability", "GoalStatus",
           "History", "InterfaceError", "MessageTypes", "MessageValueError", "Node", "Publisher",
           "Qos", "Reliability", "Responder", "ServerGoal", "ServiceClient", "ServiceError",
           "ServiceServer", "ServiceTimeoutError", "ServiceType", "SimClock", "Subscription",
           "default_context", "new_message", "to_plain"]
