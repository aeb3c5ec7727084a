"""The page's Modes panel: the mode machines of the followed trees out, force and hold in.

Owned by :class:`~cyborg.monitor.hub.Hub`; everything here runs on the web server's event loop
except :meth:`ModeLink.notify`, which the bus calls from its threads.

* **Finding machines.** For every tree runner the hub follows (``/x/bt``), the link looks in
  the bus graph every half second (the hub's periodic work) for a publisher of its latched
  ``/x/bt/mode`` and follows it through a :class:`~cyborg.monitor.mode_source.ModeSource`
  while it is there. A runner restarted on a plain tree file has none: its machine is let go.
* **To the pages:** ``{"t": "modes", "ns", "modes"}`` to each page watching that tree: ``modes``
  is null when the runner runs no mode file, else the ``mode`` now, ``held``, ``entered`` (tree
  clock, s), ``count`` (transitions made), the checked ``machine`` (``initial``, ``modes``:
  name, title, tree, description, max_time, then; ``transitions``: number, from, to,
  trigger, when, event, guard, reason), ``problems`` (lines naming file, line and mode or
  transition; never an empty panel for a machine that cannot be drawn) and ``recent``, the last
  transitions heard (from, to, reason, trigger, number, time). It goes out when it changed, at
  most once per :data:`MODES_INTERVAL` per tree (the newest when the interval has passed), and
  whenever a page starts watching the tree.
* **From the pages:** ``mode_force`` {``mode``, ``reason``?}, ``mode_request`` {``mode``,
  ``reason``?} and ``mode_hold`` {``held``: bool}, each with an optional ``ns`` (default: the
  watched tree), become the runner's ``mode/set`` service (FORCE, REQUEST, HOLD or RELEASE),
  called in a worker thread. They need the control seat; ``mode`` must be one of the
  machine's modes, ``reason`` text of at most :data:`REASON_LIMIT` characters, ``held`` true or
  false. A refusal names the field (:class:`RefusalError`).
"""

from __future__ import annotations

import asyncio
import json
import logging
from collections.abc import Callable, Collection, Mapping
from typing import Any

from cyborg.interfaces.modes import ModeAction
from cyborg.monitor.client import Client
from cyborg.monitor.latest_state import LatestState
from cyborg.monitor.limits import check_namespace
from cyborg.monitor.mode_source import Listener, ModeError, ModeSource
from cyborg.monitor.off_loop import ShutdownError, in_thread
from cyborg.monitor.refusal import RefusalError
from cyborg.monitor.robot_fields import short
from cyborg.monitor.seat import ControlSeat
from cyborg.monitor.source import TreeSource

log = logging.getLogger("cyborg.monitor")

MODES_INTERVAL = 0.25
"""Shortest time between two ``modes`` messages of one tree (s): at most four a second."""
MODE_COMMANDS = ("mode_force", "mode_request", "mode_hold")
"""The page's commands to a mode machine."""
REASON_LIMIT = 200
"""Characters a page's reason for a force or request may have."""

MakeSource = Callable[[str, Listener], ModeSource]
"""``make(namespace, listener)``: follows the mode machine of the runner under ``namespace``."""


class ModeLink:
    """Connects the mode machines on the bus to the pages' Modes panels; see the module docstring.

    ``clients`` are the hub's pages, ``seat`` its control seat and ``trees`` the tree sources
    it follows (a machine is followed only beside a followed tree). Machines are made and found
    by the functions given to :meth:`use` (none until then).
    """

    def __init__(self, clients: Collection[Client], seat: ControlSeat,
                 trees: Mapping[str, TreeSource]) -> None:
        self._clients, self._seat, self._trees = clients, seat, trees
        self.sources: dict[str, ModeSource] = {}
        self._make: MakeSource | None = None
        self._discover: Callable[[], list[str]] = list
        self._loop: asyncio.AbstractEventLoop | None = None
        self._state = LatestState[str](MODES_INTERVAL, lambda namespace: self._encode(
            self.message(namespace)), self._deliver)

    def use(self, make_source: MakeSource, discover: Callable[[], list[str]]) -> None:
        """Follows machines from now on: ``discover()`` lists the runners that serve one."""
        self._make, self._discover = make_source, discover

    def attach(self, loop: asyncio.AbstractEventLoop) -> None:
        """Binds the link to the server's event loop; :meth:`notify` drops changes until then."""
        self._loop = loop
        self._state.attach(loop)

    def detach(self) -> None:
        """Lets go of the event loop as the server stops: changes are dropped from now on."""
        self._loop = None
        self._state.detach()

    # ------------------------------------------------------------------ the machines
    async def periodic(self) -> None:
        """Follows the machines of followed trees and lets go of the rest; from the hub's loop."""
        if self._loop is None or self._make is None:
            return
        try:
            found = set(await in_thread(self._discover))
        except ShutdownError:
            return
        for namespace, source in list(self.sources.items()):
            if namespace not in self._trees or (namespace not in found and not source.alive):
                self._release(namespace)
        for namespace in sorted(found):
            if namespace in self._trees and namespace not in self.sources:
                self.sources[namespace] = self._make(namespace, self._notifier(namespace))
                self._state.changed(namespace)

    def _release(self, namespace: str) -> None:
        source = self.sources.pop(namespace, None)
        if source is not None:
            try:
                source.destroy()
            except Exception:
                log.exception("could not stop following the modes of %s", namespace)
        self._state.changed(namespace)

    def destroy(self) -> None:
        """Stops following every machine."""
        for namespace in list(self.sources):
            self.sources.pop(namespace).destroy()

    # ------------------------------------------------------------------ to the pages
    def _notifier(self, namespace: str) -> Listener:
        return lambda: self.notify(namespace)

    def notify(self, namespace: str) -> None:
        """Called from any thread when the machine under ``namespace`` changed, came or left."""
        self._state.notify(namespace)

    def message(self, namespace: str) -> dict[str, Any]:
        """The ``modes`` message for the tree under ``namespace`` now."""
        source = self.sources.get(namespace)
        shown = source.wire() if source is not None and source.alive else None
        return {"t": "modes", "ns": namespace, "modes": shown}

    def resend(self, client: Client, namespace: str) -> None:
        """Sends ``client``, which starts watching ``namespace``, its machine as it is now."""
        client.send(self._encode(self.message(namespace)))

    def _deliver(self, namespace: str, text: str) -> None:
        if self.sources.get(namespace) is None:
            self._state.forget(namespace)  # a machine that comes back is sent at once
        for client in self._clients:
            if client.watching == namespace:
                client.send(text)

    @staticmethod
    def _encode(message: dict[str, Any]) -> str:
        return json.dumps(message, separators=(",", ":"))

    # ------------------------------------------------------------------ from the pages
    async def handle(self, client: Client, kind: str, command: dict[str, Any]) -> str:
        """Carries out a page's command to a mode machine; the runner's answer.

        Raises :class:`RefusalError` (naming the field) for a command refused before the
        bus, and :class:`~cyborg.monitor.mode_source.ModeError` when the runner refuses it or
        does not answer.
        """
        self._seat.require(client.number, client.may_control)
        try:
            namespace = check_namespace(command.get("ns") or client.watching)
        except ValueError as exc:
            raise RefusalError(f"ns: {exc}", "ns") from None
        source = self.sources.get(namespace)
        view = source.view if source is not None and source.alive else None
        if source is None or view is None:
            raise RefusalError(f"ns: the tree runner under {namespace} runs no mode file",
                                   "ns")
        if kind == "mode_hold":
            held = command.get("held")
            if not isinstance(held, bool):
                raise RefusalError(f"held is {short(held)}, not true or false", "held")
            action = ModeAction.HOLD if held else ModeAction.RELEASE
            return await in_thread(source.set_mode, action)
        if kind not in ("mode_force", "mode_request"):
            raise RefusalError(f"unknown command {kind[:40]!r}", "t")
        mode, reason = command.get("mode"), command.get("reason", "")
        names = view.mode_names()
        if not isinstance(mode, str) or mode not in names:
            listed = ", ".join(names[:12]) + (", …" if len(names) > 12 else "")
            raise RefusalError(f"mode is {short(mode)}, not one of the machine's modes "
                                   f"({listed or 'none could be read'})", "mode")
        if not isinstance(reason, str) or len(reason) > REASON_LIMIT:
            raise RefusalError(f"reason is {short(reason)}, not text of at most "
                                   f"{REASON_LIMIT} characters", "reason")
        action = ModeAction.FORCE if kind == "mode_force" else ModeAction.REQUEST
        return await in_thread(source.set_mode, action, mode, reason)


__all__ = ["MODE_COMMANDS", "ModeError", "ModeLink", "RefusalError"]
