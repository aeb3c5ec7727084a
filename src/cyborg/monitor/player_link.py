"""The page's timeline over a played recording: the player's state out, pause/seek/step in.

Owned by :class:`~cyborg.monitor.hub.Hub`; everything here runs on the web server's event loop
except :meth:`PlayerLink.notify`, which the bus calls from its threads.

* **Finding the player.** ``cyborg play`` serves the contract of
  :mod:`cyborg.interfaces.player` under its namespace (``/`` by default). The link looks for a
  publisher of a ``<ns>/player/state`` topic in the bus graph every half second (the hub's
  periodic work) and follows one player at a time, the first by name (there is normally one),
  through a :class:`~cyborg.monitor.player_source.PlayerSource`. One that left is let go, and
  another is followed once one is there.
* **To the pages:** ``{"t": "player", "player": {...}}`` with the played file's name,
  ``duration``, ``position`` (s from the first message), ``rate``, ``paused``, ``finished``,
  ``time`` (the recording's time at the position, s since the epoch), the player's ``ns`` and
  ``jumps``; ``"player": null`` when no player is there (or it left). It goes to every page,
  when it changed, at most once per :data:`PLAYER_INTERVAL` (the newest state goes out when
  the interval has passed), and to a page that says hello.
* **A jump** is the position going backwards (a seek back, a loop starting over) or a seek the
  monitor made: ``jumps`` counts one more, which tells a page showing the history of ticks to
  go back to the tree as played. The history the monitor keeps never mixes two timelines: the
  player sends the latched topics again at a seek, the tree's structure first, and a structure
  starts the tree's state, history and all, over (before the recent tick the player sends
  next). A tree whose structure did not come again since the previous state (a seek to the
  start, before the structure's own message) starts over when the position goes backwards:
  nothing of it has run yet at that time.
* **From the pages:** ``player_pause`` {``paused``: bool}, ``player_seek`` {``position``: s,
  a finite number from 0 to the duration} and ``player_step`` {} become the player's
  services, called in a worker thread. They need the control seat, as every command that
  changes what the robot's side does; a refusal names the field at fault
  (:class:`RefusalError`).
"""

from __future__ import annotations

import asyncio
import json
import logging
import math
from collections.abc import Callable, Collection, Mapping
from typing import Any

from cyborg.monitor.client import Client
from cyborg.monitor.latest_state import LatestState
from cyborg.monitor.off_loop import ShutdownError, in_thread
from cyborg.monitor.player_source import Listener, PlayerError, PlayerSource
from cyborg.monitor.refusal import RefusalError
from cyborg.monitor.robot_fields import short
from cyborg.monitor.seat import ControlSeat
from cyborg.monitor.source import TreeSource

log = logging.getLogger("cyborg.monitor")

PLAYER_INTERVAL = 0.25
"""Shortest time between two ``player`` messages (s): at most four a second."""
BACKWARDS = 1e-3
"""Seconds the position must go back by to count as a jump (not rounding)."""
PLAYER_COMMANDS = ("player_pause", "player_seek", "player_step")
"""The page's commands to the player."""
PLAYER = "player"
"""The one key of the player's state (a monitor follows one player)."""

MakeSource = Callable[[str, Listener], PlayerSource]
"""``make(namespace, listener)``: follows the player under ``namespace``."""


class PlayerLink:
    """Connects the player on the bus to every page's timeline; see the module docstring.

    ``clients`` are the hub's pages, ``seat`` its control seat and ``trees`` the tree sources
    it follows (their histories are cleared at a jump). Players are made and found by the
    functions given to :meth:`use` (none until then).
    """

    def __init__(self, clients: Collection[Client], seat: ControlSeat,
                 trees: Mapping[str, TreeSource]) -> None:
        self._clients, self._seat, self._trees = clients, seat, trees
        self.source: PlayerSource | None = None
        self.jumps = 0
        self._make: MakeSource | None = None
        self._discover: Callable[[], list[str]] = list
        self._loop: asyncio.AbstractEventLoop | None = None
        self._position: float | None = None
        self._generations: dict[str, int] = {}
        """Each tree's structure generation at the previous state."""
        self._state = LatestState[str](PLAYER_INTERVAL, lambda _key: json.dumps(
            self.message(), separators=(",", ":")), self._deliver, self._look)

    def use(self, make_source: MakeSource, discover: Callable[[], list[str]]) -> None:
        """Follows players from now on: ``discover()`` lists their namespaces on the bus."""
        self._make, self._discover = make_source, discover

    def attach(self, loop: asyncio.AbstractEventLoop) -> None:
        """Binds the link to the server's event loop; :meth:`notify` drops changes until then."""
        self._loop = loop
        self._state.attach(loop)

    def detach(self) -> None:
        """Lets go of the event loop as the server stops: changes are dropped from now on."""
        self._loop = None
        self._state.detach()

    # ------------------------------------------------------------------ the player
    async def periodic(self) -> None:
        """Lets go of a player that left and follows one that is there; from the hub's loop."""
        if self._loop is None or self._make is None:
            return
        try:
            found = await in_thread(self._discover)
        except ShutdownError:
            return
        source = self.source
        if source is not None and not source.alive and source.namespace not in found:
            self._release()
        if self.source is None and found and self._loop is not None:
            self.source = self._make(found[0], self.notify)
            self._position = None
            self._state.changed(PLAYER)

    def _release(self) -> None:
        source, self.source = self.source, None
        if source is not None:
            try:
                source.destroy()
            except Exception:
                log.exception("could not stop following the player %s", source.namespace)
        self._state.changed(PLAYER)

    def destroy(self) -> None:
        """Stops following the player."""
        source, self.source = self.source, None
        if source is not None:
            source.destroy()

    # ------------------------------------------------------------------ to the pages
    def notify(self) -> None:
        """Called from any thread when the player's state changed, or it came or left."""
        self._state.notify(PLAYER)

    def message(self) -> dict[str, Any]:
        """The ``player`` message for the player's state now (``player`` null when none)."""
        source = self.source
        view = source.view if source is not None and source.alive else None
        if source is None or view is None:
            return {"t": "player", "player": None}
        return {"t": "player", "player": {**view.wire(), "ns": source.namespace,
                                          "jumps": self.jumps}}

    def resend(self, client: Client) -> None:
        """Sends ``client`` the player's state as the pages have it (a page saying hello)."""
        client.send(self._state.sent(PLAYER) or json.dumps(self.message(), separators=(",", ":")))

    def _look(self, _key: str) -> None:
        """Every change, before any send: a played time gone back is a jump."""
        source = self.source
        view = source.view if source is not None else None
        if view is not None:
            if self._position is not None and view.position < self._position - BACKWARDS:
                self._jump()
            self._position = view.position
            self._generations = {name: tree.generation for name, tree in self._trees.items()}

    def _deliver(self, _key: str, text: str) -> None:
        for client in self._clients:
            client.send(text)

    def _jump(self) -> None:
        """The played time went back: the pages are told; trees not started over start over."""
        self.jumps += 1
        for name, tree in list(self._trees.items()):
            if tree.generation == self._generations.get(name):
                tree.start_over()

    # ------------------------------------------------------------------ from the pages
    async def handle(self, client: Client, kind: str, command: dict[str, Any]) -> str:
        """Carries out a page's command to the player; the player's answer.

        Raises :class:`RefusalError` (naming the field) for a command that is refused
        before the bus, and :class:`~cyborg.monitor.player_source.PlayerError` when the player
        refuses it or does not answer.
        """
        self._seat.require(client.number, client.may_control)
        source = self.source
        view = source.view if source is not None and source.alive else None
        if source is None or view is None:
            raise RefusalError("no recording is played: no player is on the bus "
                                     "(start one with cyborg play)")
        if kind == "player_pause":
            paused = command.get("paused")
            if not isinstance(paused, bool):
                raise RefusalError(f"paused is {short(paused)}, not true or false",
                                         "paused")
            return await in_thread(source.set_paused, paused)
        if kind == "player_seek":
            position = seek_position(command.get("position"), view.duration)
            answer = await in_thread(source.seek, position)
            self.jumps += 1  # (its state, when it went back, clears what needs clearing)
            self._state.send_soon(PLAYER)
            return answer
        if kind == "player_step":
            return await in_thread(source.step)
        raise RefusalError(f"unknown command {kind[:40]!r}", "t")


def seek_position(value: Any, duration: float) -> float:
    """``value`` as a position to seek to, within 0 to ``duration`` s.

    :class:`RefusalError` naming ``position`` otherwise.
    """
    if isinstance(value, bool) or not isinstance(value, int | float) \
            or not math.isfinite(value):
        raise RefusalError(f"position is {short(value)}, not a finite number of "
                                 "seconds", "position")
    if not 0 <= value <= duration:
        raise RefusalError(f"position {value} s is outside the recording (0 to "
                                 f"{duration:.3f} s)", "position")
    return float(value)


__all__ = [
    "PLAYER_COMMANDS",
    "PlayerError",
    "PlayerLink",
    "RefusalError",
    "seek_position",
]
