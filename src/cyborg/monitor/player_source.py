"""One player of a recording (``cyborg play``), followed over the bus for the page's timeline.

A :class:`PlayerSource` subscribes to the player's latched ``<ns>/player/state``
(cyborg_msgs/PlayerState, the contract of :mod:`cyborg.interfaces.player`) and keeps the
latest as a :class:`PlayerView`: what the page's timeline draws, checked on arrival (a state
whose numbers are not finite, or whose position lies outside its duration, cannot be drawn and
is dropped with a warning in the log). Its callbacks run on the monitor node's thread and only
check, store and tell the listener.

Scrubbing goes through the player's services, ``pause`` (std_srvs/SetBool), ``seek``
(cyborg_msgs/Seek) and ``step`` (std_srvs/Trigger), as blocking calls: call them from a worker
thread. Each returns the player's answer, or raises :class:`PlayerError` with why it failed.

Liveness comes from the bus graph: the player is there while something publishes its state.
"""

from __future__ import annotations

import logging
import math
import threading
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import PurePath
from typing import Any

from cyborg.bus import Node
from cyborg.bus.msgs.cyborg_msgs.msg import PlayerState
from cyborg.bus.msgs.cyborg_msgs.srv import Seek_Request
from cyborg.bus.msgs.std_srvs.srv import SetBool_Request, Trigger_Request
from cyborg.bus.wire import EntityKind
from cyborg.interfaces import player as contract

log = logging.getLogger("cyborg.monitor")

SERVICE_TIMEOUT = 5.0
"""Seconds a call to the player's services may take before it is given up."""
FILE_NAME_LIMIT = 200
"""Characters of the played file's name sent to pages."""

Listener = Callable[[], None]
"""Told (from the bus thread) that the state changed or the player left."""


class PlayerError(RuntimeError):
    """The player refused a request or did not answer; the message says which and why."""


@dataclass(frozen=True)
class PlayerView:
    """One state of the player, as the page's timeline draws it (seconds from the start)."""

    file: str
    """The played file's name (without its folder)."""
    duration: float
    position: float
    rate: float
    paused: bool
    finished: bool
    time: float
    """The recording's time at the position: its log time, seconds since the epoch."""

    def wire(self) -> dict[str, Any]:
        """The fields of the page's ``player`` message (times to the millisecond)."""
        return {"file": self.file, "duration": round(self.duration, 3),
                "position": round(self.position, 3), "rate": self.rate,
                "paused": self.paused, "finished": self.finished, "time": round(self.time, 3)}


def view_of(state: PlayerState) -> PlayerView:
    """``state`` checked for drawing; ValueError naming the field that cannot be drawn."""
    numbers = {"duration": state.duration, "position": state.position, "rate": state.rate}
    for name, value in numbers.items():
        if not math.isfinite(value):
            raise ValueError(f"{name} is {value}, not a finite number")
    if state.duration < 0:
        raise ValueError(f"duration is {state.duration} s, below 0")
    if not 0 <= state.position <= state.duration + 1e-6:
        raise ValueError(f"position {state.position} s lies outside the recording (0 to "
                         f"{state.duration} s)")
    if state.rate <= 0:
        raise ValueError(f"rate is {state.rate}, not a speed above 0")
    name = PurePath(state.source).name or state.source
    time = state.recording_time.sec + state.recording_time.nanosec * 1e-9
    return PlayerView(file=name[:FILE_NAME_LIMIT], duration=float(state.duration),
                      position=min(float(state.position), float(state.duration)),
                      rate=float(state.rate), paused=bool(state.paused),
                      finished=bool(state.finished), time=time)


class PlayerSource:
    """Follows the player under ``namespace``; see the module docstring."""

    def __init__(self, node: Node, namespace: str, listener: Listener) -> None:
        self.node, self.namespace = node, "/" + namespace.strip("/")
        self._listener = listener
        self.view: PlayerView | None = None
        """The latest state that could be drawn; None before the first."""
        self.alive = False
        self._lock = threading.Lock()
        ns = self.namespace
        self._subscription = contract.STATE.subscription(node, self._on_state, ns)
        self._pause = contract.PAUSE.client(node, ns)
        self._seek = contract.SEEK.client(node, ns)
        self._step = contract.STEP.client(node, ns)
        self._warned = ""
        self._remove_graph_listener = node.context.graph.on_change(self._check_alive)
        self._check_alive()

    def _on_state(self, message: PlayerState) -> None:
        try:
            view = view_of(message)
        except ValueError as exc:
            if str(exc) != self._warned:  # once per reason, not at 4 Hz
                self._warned = str(exc)
                log.warning("%s: %s", contract.STATE.full_name(self.namespace), exc)
            return
        with self._lock:
            self.view = view
        self._tell()

    def _check_alive(self) -> None:
        alive = self.node.context.graph.count(contract.STATE.full_name(self.namespace),
                                              EntityKind.PUBLISHER) > 0
        if alive != self.alive:
            self.alive = alive
            self._tell()

    def _tell(self) -> None:
        try:
            self._listener()
        except Exception:
            log.exception("monitor listener failed on the player %s", self.namespace)

    # ------------------------------------------------------------------ services out
    def set_paused(self, paused: bool) -> str:
        """Pauses (True) or resumes (False) the player; its answer."""
        return self._call(contract.PAUSE.full_name(self.namespace),
                          lambda: self._pause.call(SetBool_Request(data=paused),
                                                   timeout=SERVICE_TIMEOUT))

    def seek(self, position: float) -> str:
        """Moves the player to ``position`` (s from the start); its answer."""
        return self._call(contract.SEEK.full_name(self.namespace),
                          lambda: self._seek.call(Seek_Request(position=position),
                                                  timeout=SERVICE_TIMEOUT))

    def step(self) -> str:
        """Plays the next message and stays paused; the player's answer."""
        return self._call(contract.STEP.full_name(self.namespace),
                          lambda: self._step.call(Trigger_Request(), timeout=SERVICE_TIMEOUT))

    @staticmethod
    def _call(name: str, call: Callable[[], Any]) -> str:
        """The message of the answer ``call()`` gets; :class:`PlayerError` when refused."""
        try:
            response = call()
        except Exception as exc:
            raise PlayerError(f"{name}: {exc}") from exc
        if not response.success:
            raise PlayerError(f"{name}: {response.message}")
        return str(response.message)

    def destroy(self) -> None:
        """Withdraws the subscription and the service clients; the listener hears no more."""
        self._remove_graph_listener()
        self._listener = _ignore
        self._subscription.destroy()
        for client in (self._pause, self._seek, self._step):
            client.destroy()


def _ignore() -> None:
    """The listener of a source that was destroyed."""
