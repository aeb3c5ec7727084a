"""The player's interface, between ``cyborg play`` and whoever scrubs its timeline.

What :mod:`cyborg.record.player` serves and a timeline (the monitor's, or ``cyborg service
call``) uses. Under the player's node, ``<namespace>/player`` (:data:`NAME`; the namespace is
``/`` unless ``cyborg play --namespace`` gives another):

==========  ============================  ================================================
name        type                          what
==========  ============================  ================================================
``state``   cyborg_msgs/PlayerState       latched: position, duration, rate, paused,
                                          finished, the recording's time, the file
``pause``   std_srvs/SetBool              true pauses, false resumes
``seek``    cyborg_msgs/Seek              go to a position (seconds from the start)
``step``    std_srvs/Trigger              play the next message, then stay paused
==========  ============================  ================================================

The state is published when anything changes and every :data:`STATE_PERIOD` seconds of play.
"""

from __future__ import annotations

from cyborg.bus.msgs.cyborg_msgs.msg import PlayerState
from cyborg.bus.msgs.cyborg_msgs.srv import Seek
from cyborg.bus.msgs.std_srvs.srv import SetBool, Trigger
from cyborg.interfaces.contract import Service, Topic

NAME = "player"
"""The player's node name; its endpoints are ``<namespace>/player/...``."""
STATE_PERIOD = 0.25
"""Seconds of wall time between two state messages while playing."""

STATE = Topic(f"{NAME}/state", PlayerState, latched=True)
TOPICS: tuple[Topic, ...] = (STATE,)

PAUSE = Service(f"{NAME}/pause", SetBool)
SEEK = Service(f"{NAME}/seek", Seek)
STEP = Service(f"{NAME}/step", Trigger)
SERVICES: tuple[Service, ...] = (PAUSE, SEEK, STEP)


def player_namespace(topic: str, type_name: str) -> str | None:
    """The namespace of the player that publishes ``topic`` of ``type_name``, or None.

    Only a player's state topic names one (``/player/state`` → ``/``, ``/replay/player/state``
    → ``/replay``); ``type_name`` is the topic's type as the bus graph shows it.
    """
    suffix = "/" + STATE.name
    if type_name != STATE.type_name or not topic.endswith(suffix):
        return None
    return topic.removesuffix(suffix) or "/"
