"""The ``monitor`` node: follows tree runners on the bus and serves the page that shows them.

::

    monitor = Monitor(Node("monitor", "/cyborg"), namespaces=["/cyborg/bt"], port=8080)
    monitor.start()          # serves http://127.0.0.1:8080/ from a background thread
    print(monitor.urls())
    ...
    monitor.stop()

It listens on loopback unless given another ``host`` (``0.0.0.0``: every interface); then
:meth:`Monitor.exposure` says where, and whether other machines may control (with the token)
or only watch. See docs/security.md.

The bus node (``/cyborg/monitor`` by default) subscribes to each runner's topics and calls its
services (:mod:`cyborg.monitor.source`); tree runners that appear on the bus later are found by
their ``behavior_tree`` topic and offered on the page too; a player of a recording
(``cyborg play``) is found by its ``player/state`` topic and drives the page's timeline
(:mod:`cyborg.monitor.player_link`); a runner of a mode file, by its ``mode`` topic, fills the
page's Modes panel (:mod:`cyborg.monitor.mode_link`). The web side
(:mod:`cyborg.monitor.server`) runs on uvicorn in its own thread.
"""

from __future__ import annotations

import ipaddress
import logging
import socket
import threading
import time
from functools import partial
from typing import Any

import uvicorn

from cyborg.bus import Node
from cyborg.bus.wire import EntityKind
from cyborg.interfaces import modes, player, robot, tree_runner
from cyborg.monitor.access import TOKEN_VARIABLE, HostPolicy, read_token
from cyborg.monitor.hub import Hub
from cyborg.monitor.limits import FRAME_LIMIT, Limits, check_namespace
from cyborg.monitor.mode_source import ModeSource
from cyborg.monitor.player_source import PlayerSource
from cyborg.monitor.robot_clients import RobotClients
from cyborg.monitor.robot_source import RobotSource
from cyborg.monitor.seat import ControlSeat
from cyborg.monitor.server import create_app
from cyborg.monitor.source import TreeSource

log = logging.getLogger("cyborg.monitor")

__all__ = ["DEFAULT_HOST", "DEFAULT_PORT", "TOKEN_VARIABLE", "Monitor", "MonitorError"]

DEFAULT_PORT = 8080
DEFAULT_HOST = "127.0.0.1"
EVERY_INTERFACE = ("0.0.0.0", "::", "")


class MonitorError(RuntimeError):
    """The monitor cannot start (say, its port is taken); the message says what to do."""


class Monitor:
    """The monitor: follows tree runners through ``node`` and serves their page once started.

    It follows the tree runners under ``namespaces`` (and any found later) and serves on
    ``host:port`` (port 0: any free port); see the module docstring. Control from other
    machines needs ``token`` (default: ``$CYBORG_MONITOR_TOKEN``); requests must name this
    machine, or one of ``allow_hosts`` (see :class:`~cyborg.monitor.access.HostPolicy`);
    ``limits`` bounds what viewers cost. ``ValueError`` for a namespace that is not one.
    """

    def __init__(self, node: Node, *, namespaces: list[str] | None = None,
                 host: str = DEFAULT_HOST, port: int = DEFAULT_PORT,
                 token: str | None = None, allow_hosts: list[str] | tuple[str, ...] = (),
                 limits: Limits | None = None) -> None:
        self.node = node
        self.host, self.requested_port = host, port
        namespaces = [check_namespace(namespace)
                      for namespace in namespaces or [tree_runner.NAMESPACE]]
        self.hub = Hub(self._make_source, self.discover, default_namespace=namespaces[0],
                       seat=ControlSeat(read_token(token)), limits=limits)
        for namespace in namespaces:
            self.hub.follow(namespace, pinned=True)
        self.hub.robot_hub.use(self._make_robot, self.discover_robots)
        self.hub.robot_commands.use(partial(RobotClients, self.node))
        self.hub.player.use(partial(PlayerSource, self.node), self.discover_players)
        self.hub.modes.use(partial(ModeSource, self.node), self.discover_modes)
        names = [*allow_hosts, host] if host not in EVERY_INTERFACE else list(allow_hosts)
        self.hosts = HostPolicy(names)
        self.app = create_app(self.hub, hosts=self.hosts)
        self._server: uvicorn.Server | None = None
        self._thread: threading.Thread | None = None
        self.port = 0

    def _make_source(self, namespace: str) -> TreeSource:
        return TreeSource(self.node, namespace, self.hub.notify)

    def discover(self) -> list[str]:
        """Namespaces of the tree runners on the bus (found by their structure topic)."""
        found = {tree_runner.runner_namespace(entity.topic, entity.type_name)
                 for entity in self.node.context.graph.entities([EntityKind.PUBLISHER])}
        return sorted(namespace for namespace in found if namespace is not None)

    def _make_robot(self, namespace: str) -> RobotSource:
        return RobotSource(self.node, namespace, self.hub.robot_hub.notify)

    def discover_robots(self) -> list[str]:
        """Namespaces of the robots on the bus (found by their pose topic)."""
        found = {robot.robot_namespace(entity.topic, entity.type_name)
                 for entity in self.node.context.graph.entities([EntityKind.PUBLISHER])}
        return sorted(namespace for namespace in found if namespace is not None)

    def discover_players(self) -> list[str]:
        """Namespaces of the players of recordings on the bus (found by their state topic)."""
        found = {player.player_namespace(entity.topic, entity.type_name)
                 for entity in self.node.context.graph.entities([EntityKind.PUBLISHER])}
        return sorted(namespace for namespace in found if namespace is not None)

    def discover_modes(self) -> list[str]:
        """Namespaces of the tree runners that run a mode file (found by their mode topic)."""
        found = {modes.machine_namespace(entity.topic, entity.type_name)
                 for entity in self.node.context.graph.entities([EntityKind.PUBLISHER])}
        return sorted(namespace for namespace in found if namespace is not None)

    # ------------------------------------------------------------------ serving
    def start(self, timeout: float = 10.0) -> None:
        """Bind the port (:class:`MonitorError` if taken) and serve in a background thread."""
        listener = _bind(self.host, self.requested_port)
        self.port = listener.getsockname()[1]
        config = uvicorn.Config(self.app, log_level="warning", lifespan="on",
                                ws_per_message_deflate=False, ws_max_size=FRAME_LIMIT)
        server = self._server = uvicorn.Server(config)
        self._thread = threading.Thread(target=server.run, kwargs={"sockets": [listener]},
                                        name="cyborg-monitor-web", daemon=True)
        self._thread.start()
        deadline = time.monotonic() + timeout
        while not server.started:
            if not self._thread.is_alive() or time.monotonic() > deadline:
                raise MonitorError(f"the monitor's web server did not start within "
                                   f"{timeout:g} s")
            time.sleep(0.01)
        log.info("monitor serving on %s", ", ".join(self.urls()))
        exposure = self.exposure()
        if exposure:
            log.info("monitor %s", exposure)

    @property
    def on_loopback(self) -> bool:
        """Whether the monitor listens on this machine's loopback only."""
        if self.host == "localhost":
            return True
        try:
            return ipaddress.ip_address(self.host).is_loopback
        except ValueError:
            return False

    def exposure(self) -> str | None:
        """Where a monitor listening beyond loopback is exposed; None on loopback.

        The text says where it listens, and whether other machines may control (with the
        token) or only watch.
        """
        if self.on_loopback:
            return None
        every = " (every interface)" if self.host in EVERY_INTERFACE else ""
        host = f"[{self.host}]" if ":" in self.host else self.host
        control = ("a token is set: other machines control with it (open ?token=...)"
                   if self.hub.seat.token else "no token: other machines may only watch")
        return f"listening on {host}:{self.port}{every}; {control}"

    def urls(self) -> list[str]:
        """Addresses to open in a browser (this machine first)."""
        urls = [f"http://127.0.0.1:{self.port}/"]
        if self.host not in ("127.0.0.1", "localhost", "::1"):
            address = _lan_address()
            if self.host not in ("0.0.0.0", "::"):
                address = self.host
            if address:
                urls.append(f"http://{address}:{self.port}/")
        return urls

    def stop(self) -> None:
        """Stop serving and leave the bus (hooks set from the page are released with it)."""
        if self._server is not None:
            self._server.should_exit = True
        if self._thread is not None:
            self._thread.join(10.0)
            self._thread = None
        for source in list(self.hub.sources.values()):
            source.destroy()
        self.hub.robot_commands.destroy()
        self.hub.robot_hub.destroy()
        self.hub.player.destroy()
        self.hub.modes.destroy()
        self.node.destroy()

    def __enter__(self) -> Monitor:
        self.start()
        return self

    def __exit__(self, *_exc: Any) -> None:
        self.stop()


def _bind(host: str, port: int) -> socket.socket:
    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    listener = socket.socket(family, socket.SOCK_STREAM)
    listener.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    try:
        listener.bind((host, port))
    except OSError as exc:
        listener.close()
        raise MonitorError(f"the monitor cannot listen on {host}:{port} ({exc.strerror}); "
                           "choose another port with --port (or --monitor-port)") from None
    listener.listen(128)
    listener.setblocking(False)
    return listener


def _lan_address() -> str | None:
    """This machine's address on its main network (no packet is sent)."""
    probe = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        probe.connect(("192.0.2.1", 9))
        address: str = probe.getsockname()[0]
    except OSError:
        return None
    finally:
        probe.close()
    return None if address.startswith("127.") else address
