"""Messaging for cyborg's programs, on Zenoh and wire-compatible with ROS 2 (rmw_zenoh).

So far: ROS 2 message, service and action types with CDR and RIHS01 type hashes
(:mod:`cyborg.bus.message_types`, :mod:`cyborg.bus.type_hash`), and rmw_zenoh's keys, liveliness
tokens, QoS strings, GIDs and attachments (:mod:`cyborg.bus.wire`). This package imports nothing
else of cyborg.
"""

from cyborg.bus.message_types import BUNDLED_INTERFACES, InterfaceError, MessageTypes

__all__ = ["BUNDLED_INTERFACES", "InterfaceError", "MessageTypes"]
