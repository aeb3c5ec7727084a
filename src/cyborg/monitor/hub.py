"""The monitor's switchboard: tree runners on one side, browsers on the other.

Everything here runs on the web server's event loop. The bus side calls :meth:`Hub.notify` from
its own threads; the hub picks it up with ``call_soon_threadsafe``, so neither the tree nor the
bus ever waits for a browser.

* **Ticks** are coalesced: at most one frame per :data:`FRAME_INTERVAL` per tree, each frame
  holding only the nodes whose display changed (see :mod:`cyborg.monitor.tree_state`). A frame
  is encoded once and queued to every browser watching that tree.
* **Structures** go to a browser when it starts showing a tree (a namespace and version) it
  does not show now: once per version while it stays on one robot, again when it comes back
  to a robot it left (the page keeps only the tree it draws). A restarted runner with the same
  tree only resets the statuses.
* **Commands** from browsers are checked against the control seat (:mod:`cyborg.monitor.seat`,
  which knows pages by connection number and sends its secret to its holder alone) and run as
  blocking service calls in worker threads; each gets a ``result`` reply.
* Every :data:`SLOW_PERIOD` the hub sends per-node timings, polls blackboards of watched trees,
  looks for new tree runners on the bus and frees the seat of a holder gone too long.
* **What viewers cost** is bounded (:mod:`cyborg.monitor.limits`). A tree is followed (one
  :class:`TreeSource`, shared by every page that watches it) when the monitor was started with
  it (*pinned*) or while its runner is on the bus; once the runner has left and no page watches
  it, it is freed with all kept for it. Watching a namespace no runner is in subscribes to
  nothing. Connections are counted per address.
* **Robots**: their maps in :attr:`Hub.robot_hub`, acting on them in :attr:`Hub.robot_commands`;
  a played recording's timeline in :attr:`Hub.player` (:mod:`cyborg.monitor.player_link`);
  the trees' mode machines in :attr:`Hub.modes` (:mod:`cyborg.monitor.mode_link`) and the
  services on their composites in :attr:`Hub.services` (:mod:`cyborg.monitor.service_link`).
"""

from __future__ import annotations

import asyncio
import contextlib
import itertools
import json
import logging
import time
from collections.abc import Callable
from typing import Any

from starlette.websockets import WebSocket

from cyborg.monitor.client import Client
from cyborg.monitor.limits import Limits, check_namespace
from cyborg.monitor.mode_link import ModeLink
from cyborg.monitor.off_loop import ShutdownError, in_thread
from cyborg.monitor.player_link import PlayerLink
from cyborg.monitor.refusal import RefusalError
from cyborg.monitor.robot_commands import RobotCommands
from cyborg.monitor.robot_hub import RobotHub
from cyborg.monitor.seat import ControlSeat
from cyborg.monitor.service_link import ServiceLink
from cyborg.monitor.source import ControlError, TreeSource

log = logging.getLogger("cyborg.monitor")

FRAME_INTERVAL = 1 / 60
"""Shortest time between two frames of one tree (ticks in between are merged)."""
SLOW_PERIOD = 0.5
FOLLOW_LIMIT = 128
"""Most trees the monitor follows at once (runners beyond are not listed, with a warning)."""


class LimitError(RefusalError):
    """A page asked for more than :class:`Limits` allow; the message says which limit."""


def encode(message: dict[str, Any]) -> str:
    """Compact JSON text of a message to the pages."""
    return json.dumps(message, separators=(",", ":"))


class Hub:
    """Connects :class:`TreeSource` objects to browser :class:`Client` objects."""

    def __init__(self, make_source: Callable[[str], TreeSource],
                 discover: Callable[[], list[str]], *, default_namespace: str,
                 seat: ControlSeat, limits: Limits | None = None) -> None:
        self._make_source, self._discover = make_source, discover
        self.default_namespace = default_namespace
        self.sources: dict[str, TreeSource] = {}
        self.pinned: set[str] = set()
        """Namespaces followed for good: the ones the monitor was started with."""
        self.limits = limits or Limits()
        self.seat = seat
        self.clients: set[Client] = set()
        self._loop: asyncio.AbstractEventLoop | None = None
        self._scheduled: set[str] = set()
        self._last_frame: dict[str, float] = {}
        self._blackboards: dict[str, str] = {}
        self._numbers = itertools.count(1)
        self._warned_limit, self.frames = False, 0
        self.robot_hub = RobotHub(self.clients, self.sources,
                                  lambda: self.broadcast(self.robots()))
        self.robot_commands = RobotCommands(self.clients, seat, self.sources, self.robot_hub)
        self.player = PlayerLink(self.clients, seat, self.sources)
        self.modes = ModeLink(self.clients, seat, self.sources)
        self.services = ServiceLink(self.clients, self.sources)

    # ------------------------------------------------------------------ sources
    def follow(self, namespace: str, *, pinned: bool = False) -> TreeSource:
        """The source following ``namespace`` (a checked name), created on first use.

        ``pinned``: followed for good (the trees the monitor was started with).
        """
        found = self.sources.get(namespace)
        if found is None:
            found = self.sources[namespace] = self._make_source(namespace)
        if pinned:
            self.pinned.add(namespace)
        return found

    def _release(self, namespace: str | None) -> bool:
        """Stops following ``namespace`` if nothing needs it any more; whether it was freed.

        Nothing needs it when it is not pinned, no page watches it and its runner has gone from
        the bus; all kept for it is freed then.
        """
        if namespace is None or namespace in self.pinned or self._watchers(namespace):
            return False
        source = self.sources.get(namespace)
        if source is not None and source.alive:
            return False
        self.sources.pop(namespace, None)
        for kept in (self._last_frame, self._blackboards):
            kept.pop(namespace, None)
        self.services.forget(namespace)
        self._scheduled.discard(namespace)
        if source is None:
            return False
        try:
            source.destroy()
        except Exception:
            log.exception("could not stop following %s", namespace)
        return True

    def watch(self, client: Client, namespace: Any) -> None:
        """Makes ``client`` watch ``namespace`` (any value: checked here) and sends it the tree.

        A namespace with no runner on the bus costs nothing: no source is made for it (the
        periodic look follows its runner once one appears). ``ValueError`` for a bad name,
        :class:`LimitError` past :attr:`Limits.namespaces_per_connection`.
        """
        namespace = check_namespace(namespace)
        found = False
        if namespace not in self.sources:
            if namespace in self._discover():  # on the bus, and not looked for yet
                found = self._found(namespace)
            elif namespace not in client.asked:
                limit = self.limits.namespaces_per_connection
                if len(client.asked) >= limit:
                    raise LimitError(f"a page may watch at most {limit} namespaces that no "
                                     "tree runner is in; reload the page to start again")
                client.asked.add(namespace)
        previous, client.watching = client.watching, namespace
        client.send({"t": "watching", "ns": namespace})
        self.send_tree(client, namespace)
        freed = previous != namespace and self._release(previous)
        if found or freed:
            self.broadcast(self.robots())

    def robots(self) -> dict[str, Any]:
        """The ``robots`` message: the followed trees, the seat's holder, the map's robots."""
        return {"t": "robots", "robots": [self.sources[name].describe()
                                          for name in sorted(self.sources)],
                "seat": self.seat.holder.client if self.seat.holder else None,
                "map_robots": self.robot_hub.describe()}

    # ------------------------------------------------------------------ from the bus
    def notify(self, namespace: str, what: str) -> None:
        """Called from any thread when ``what`` changed for the tree under ``namespace``."""
        loop = self._loop
        if loop is None or loop.is_closed():
            return
        if what == "services":
            self.services.notify(namespace)
        elif what == "tick":
            if namespace in self._scheduled:
                return
            self._scheduled.add(namespace)
        with contextlib.suppress(RuntimeError):  # the loop closed meanwhile
            loop.call_soon_threadsafe(self._on_change, namespace, what)

    def _on_change(self, namespace: str, what: str) -> None:
        if what == "tick":
            delay = self._last_frame.get(namespace, 0.0) + FRAME_INTERVAL - time.monotonic()
            assert self._loop is not None
            if delay > 0:
                self._loop.call_later(delay, self._flush, namespace)
            else:
                self._flush(namespace)
            return
        self.robot_hub.tree_changed(namespace)  # (a tick: in _flush, with the newest state)
        if what == "structure":
            for client in self._watchers(namespace):
                self.send_tree(client, namespace)
            self.broadcast(self.robots())
        else:
            source = self.sources.get(namespace)
            if source is not None:
                runner = encode(self._runner_message(source))
                for client in self._watchers(namespace):
                    client.send(runner)
            self.broadcast(self.robots())

    def _flush(self, namespace: str) -> None:
        self._scheduled.discard(namespace)
        self._last_frame[namespace] = time.monotonic()
        source = self.sources.get(namespace)
        state = source.state if source is not None else None
        self.robot_hub.tree_changed(namespace)
        watchers = self._watchers(namespace)
        if state is None or not watchers:
            return  # a page that starts watching gets a snapshot
        frame = state.frame()
        if frame is None:
            return
        frame["ns"] = namespace
        text = encode(frame)
        self.frames += 1
        shown = (namespace, state.version)
        for client in watchers:
            if client.shown == shown:
                client.send(text)

    # ------------------------------------------------------------------ to browsers
    def _watchers(self, namespace: str) -> list[Client]:
        return [client for client in self.clients if client.watching == namespace]

    def broadcast(self, message: dict[str, Any]) -> None:
        """Queues ``message`` to every connected page, encoded once."""
        text = encode(message)
        for client in self.clients:
            client.send(text)

    def _runner_message(self, source: TreeSource) -> dict[str, Any]:
        return {"t": "runner", "ns": source.namespace, "alive": source.alive,
                "enabled": source.enabled, "stopped": source.stopped, "hooks": source.hooks,
                "paused_at": source.paused_at, "problem": source.problem}

    def send_tree(self, client: Client, namespace: str) -> None:
        """Sends ``client`` everything about the tree under ``namespace``.

        That is the runner's state, its mode machine, the structure (unless the client shows
        this very tree now), a snapshot, the timings and the last blackboard; for a namespace
        no runner is in, that there is none.
        """
        source = self.sources.get(namespace)
        self.modes.resend(client, namespace)
        client.send(self._runner_message(source) if source is not None else
                    {"t": "runner", "ns": namespace, "alive": False, "enabled": None,
                     "stopped": None, "hooks": [], "paused_at": "", "problem": ""})
        state = source.state if source is not None else None
        if source is None or state is None:
            client.shown = None
            client.send({"t": "structure", "ns": namespace, "v": None, "tree": None})
            return
        if client.shown != (namespace, state.version):
            client.shown = (namespace, state.version)
            client.send('{"t":"structure","ns":' + json.dumps(namespace) + ',"v":"'
                        + state.version + '","tree":' + state.text + "}")
        snapshot = state.snapshot()
        snapshot["ns"] = namespace
        snapshot["generation"] = source.generation
        client.send(snapshot)
        client.send({"t": "timing", "ns": namespace, "v": state.version,
                     "nodes": state.timings(all_nodes=True)})
        blackboard = self._blackboards.get(namespace)
        if blackboard is not None:
            client.send(blackboard)
        self.services.send_to(client, namespace)

    def resync(self, client: Client) -> None:
        """Send a client that fell behind everything again."""
        client.shown = None
        if client.watching is not None:
            self.send_tree(client, client.watching)
        self.robot_hub.resend(client)

    # ------------------------------------------------------------------ clients
    def attach(self, loop: asyncio.AbstractEventLoop) -> None:
        """Binds the hub to the server's event loop; :meth:`notify` drops changes until then."""
        self._loop = loop
        self.robot_hub.attach(loop)
        self.player.attach(loop)
        self.modes.attach(loop)
        self.services.attach(loop)

    def refusal(self, host: str | None) -> str | None:
        """Why one more connection from ``host`` is refused, or None when it is not."""
        return self.limits.refusal([client.host for client in self.clients], host)

    def connect(self, websocket: WebSocket, *, may_control: bool) -> Client:
        """A new client for an accepted ``websocket``, numbered and registered in one step.

        No other connection can come in between and get the same number.
        """
        client = Client(next(self._numbers), websocket, may_control=may_control,
                        limits=self.limits)
        self.clients.add(client)
        return client

    def disconnect(self, client: Client) -> None:
        """Forgets ``client`` and tells the others only what changed (the seat, the trees).

        Pages that come and go thus cost the pages that stay nothing.
        """
        self.clients.discard(client)
        self.robot_commands.disconnected(client)
        if self.seat.disconnected(client.number):
            self.announce_seat()
        watched, client.watching = client.watching, None
        if self._release(watched):
            self.broadcast(self.robots())

    def seat_message(self, client: Client) -> dict[str, Any]:
        """The ``seat`` message for ``client``: who holds it, and what ``client`` may do.

        The holder is named by its connection number, which nobody can present; the seat's
        secret goes only to its holder.
        """
        message = {"t": "seat", "may_control": client.may_control,
                   "control": self.seat.holds(client.number),
                   "holder": self.seat.holder.client if self.seat.holder else None}
        secret = self.seat.secret_for(client.number)
        if secret is not None:
            message["secret"] = secret
        return message

    def announce_seat(self) -> None:
        """Tells every page who holds the seat now (each its own :meth:`seat_message`)."""
        for client in self.clients:
            client.send(self.seat_message(client))

    # ------------------------------------------------------------------ periodic work
    async def run_periodic(self) -> None:
        """Timings, blackboards, discovery and seat expiry, until cancelled."""
        while True:
            await asyncio.sleep(SLOW_PERIOD)
            try:
                await self._periodic()
            except ShutdownError:
                return  # the process exits (the server's thread outlives the executors)
            except Exception:
                log.exception("monitor periodic work failed")

    async def _periodic(self) -> None:
        changed = False
        for namespace in await in_thread(self._discover):
            changed = self._found(namespace) or changed
        for namespace in list(self.sources):  # runners that left, and nobody watches
            changed = self._release(namespace) or changed
        if changed:
            self.broadcast(self.robots())
        await self.robot_hub.periodic()
        await self.player.periodic()
        await self.modes.periodic()
        watched = {client.watching for client in self.clients if client.watching}
        for namespace in watched:
            source = self.sources.get(namespace)
            state = source.state if source else None
            if source is None or state is None:
                continue
            rows = state.timings()
            if rows:
                text = encode({"t": "timing", "ns": namespace, "v": state.version,
                               "nodes": rows})
                for client in self._watchers(namespace):
                    client.send(text)
            if source.alive:
                await self._poll_blackboard(source)
        expired = self.seat.expired()
        if expired is None:
            return
        for namespace, node_id in sorted(expired):
            source = self.sources.get(namespace)
            if source is not None:
                try:
                    await in_thread(source.control, node_id, "clear")
                except ControlError as exc:
                    log.warning("could not release hook on %s: %s", node_id, exc)
        log.info("the control seat is free (its holder left); %d hook(s) released",
                 len(expired))
        self.announce_seat()

    def _found(self, namespace: str) -> bool:
        """Follows a tree runner found on the bus; whether it is new to the monitor.

        It is followed while it is there or watched, at most :data:`FOLLOW_LIMIT` at once.
        """
        if namespace in self.sources:
            return False
        try:
            namespace = check_namespace(namespace)
        except ValueError:
            return False  # not a runner's name: nothing a page could watch
        if len(self.sources) >= FOLLOW_LIMIT:
            if not self._warned_limit:
                log.warning("more than %d tree runners on the bus: the monitor lists the first",
                            FOLLOW_LIMIT)
                self._warned_limit = True
            return False
        self.follow(namespace)
        for client in self._watchers(namespace):  # pages that waited for it
            self.send_tree(client, namespace)
        return True

    async def _poll_blackboard(self, source: TreeSource) -> None:
        try:
            data = await in_thread(source.blackboard)
        except ControlError:
            return
        text = encode({"t": "blackboard", "ns": source.namespace, "data": data})
        if text != self._blackboards.get(source.namespace):
            self._blackboards[source.namespace] = text
            for client in self._watchers(source.namespace):
                client.send(text)
