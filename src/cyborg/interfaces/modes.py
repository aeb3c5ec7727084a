"""A tree runner's mode machine on the bus, between the runner and whoever watches or steers it.

What :mod:`cyborg.runner.mode_endpoints` serves when the runner runs a mode file
(docs/modes.md), and what the command line (``cyborg bt mode``) and monitors use. Under the
runner's namespace (``/cyborg/bt`` by default, as in :mod:`cyborg.interfaces.tree_runner`):

====================  ============================  ======================================
name                  type                          what
====================  ============================  ======================================
``mode``              cyborg_msgs/ModeState         latched: the current mode, the hold,
                                                    the machine as JSON
``mode/transitions``  cyborg_msgs/ModeTransition    every transition: from, to, reason,
                                                    trigger, time
``mode/events``       std_msgs/String               subscribed: each message fires the
                                                    event of that name
``mode/set``          cyborg_msgs/SetMode           service: request or force a mode, hold
                                                    or release the current one
====================  ============================  ======================================

The transitions topic is not latched (a transition is news once; the latched state counts them
and names the current mode); its publisher queues up to :data:`TRANSITION_DEPTH` messages.
"""

from __future__ import annotations

from enum import IntEnum

from cyborg.bus.msgs.cyborg_msgs.msg import ModeState, ModeTransition
from cyborg.bus.msgs.cyborg_msgs.srv import SetMode, SetMode_Request
from cyborg.bus.msgs.std_msgs.msg import String
from cyborg.interfaces.contract import Service, Topic

TRANSITION_DEPTH = 16
"""Transitions a publisher keeps in its history."""

STATE = Topic("mode", ModeState, latched=True)
TRANSITIONS = Topic("mode/transitions", ModeTransition, depth=TRANSITION_DEPTH)
EVENTS = Topic("mode/events", String)
TOPICS: tuple[Topic, ...] = (STATE, TRANSITIONS, EVENTS)

SET_MODE = Service("mode/set", SetMode)
SERVICES: tuple[Service, ...] = (SET_MODE,)


def machine_namespace(topic: str, type_name: str) -> str | None:
    """The namespace of the runner whose mode machine publishes ``topic`` of ``type_name``.

    Only a machine's state topic names one (``/cyborg/bt/mode`` → ``/cyborg/bt``); None for
    any other. ``type_name`` is the topic's type as the bus graph shows it.
    """
    suffix = "/" + STATE.name
    if type_name != STATE.type_name or not topic.endswith(suffix):
        return None
    return topic.removesuffix(suffix) or "/"


class ModeAction(IntEnum):
    """SetMode's ``action``: what the call asks of the machine."""

    REQUEST = SetMode_Request.REQUEST
    FORCE = SetMode_Request.FORCE
    HOLD = SetMode_Request.HOLD
    RELEASE = SetMode_Request.RELEASE

    @property
    def label(self) -> str:
        """Lower-case name, as the command line says it."""
        return self.name.lower()
