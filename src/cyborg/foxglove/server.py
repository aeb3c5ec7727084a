"""The Foxglove server: the bus served to the Foxglove app over its WebSocket protocol.

::

    server = FoxgloveServer(Node("foxglove", "/cyborg"), port=8765)
    server.start()      # ws://127.0.0.1:8765: open it in Foxglove ("Open connection")
    ...
    server.stop()

foxglove-sdk's server (``foxglove.start_server``) speaks the protocol (subprotocol
``foxglove.sdk.v1``, or ``foxglove.websocket.v1`` for older clients) on a free loopback port;
the :class:`~cyborg.foxglove.gate.Gate` listens on ``host:port`` in front of it and lets in
only what the rules of :mod:`cyborg.foxglove.admission` admit. The SDK's lines about what a
client sent are limited to one per client and kind per period (:mod:`cyborg.foxglove.sdk_log`).
The :class:`~cyborg.foxglove.bridge.Bridge` keeps the channels in step with the bus, and the
:class:`~cyborg.foxglove.relay.Relays` subscribe on the bus while clients watch.
"""

from __future__ import annotations

import logging

import foxglove
from foxglove.websocket import WebSocketServer

from cyborg.access import HostPolicy, read_token
from cyborg.bus import Node
from cyborg.foxglove.admission import Admission, AdmissionError, check_binding, is_loopback
from cyborg.foxglove.bridge import POLL, Bridge
from cyborg.foxglove.gate import Gate, GateError
from cyborg.foxglove.relay import LINGER, Relays
from cyborg.foxglove.sdk_log import install as limit_client_lines

log = logging.getLogger("cyborg.foxglove")

DEFAULT_PORT = 8765
"""The Foxglove WebSocket protocol's usual port (foxglove_bridge's too)."""
DEFAULT_HOST = "127.0.0.1"
"""This machine only, unless told otherwise."""
MAX_PORT = 65535
"""The highest TCP port."""


class FoxgloveError(RuntimeError):
    """The server cannot start (its port is taken, no token for the network); says what to do."""


class FoxgloveServer:
    """Serves the bus ``node`` sees on ``host:port`` (port 0: any free port) to Foxglove.

    ``token`` (default: ``$CYBORG_MONITOR_TOKEN``) lets other machines in, and is required to
    listen beyond loopback; ``allow_hosts`` adds names the server answers to and
    ``allow_origins`` web pages that may connect from this machine without the token (see
    :mod:`cyborg.foxglove.admission`); ``linger``: seconds a channel's bus subscription
    outlives its last client. ValueError for a port that is not one.
    """

    def __init__(self, node: Node, *, host: str = DEFAULT_HOST, port: int = DEFAULT_PORT,
                 token: str | None = None, allow_hosts: list[str] | tuple[str, ...] = (),
                 allow_origins: list[str] | tuple[str, ...] = (), poll: float = POLL,
                 linger: float = LINGER) -> None:
        if not 0 <= port <= MAX_PORT:
            raise ValueError(f"port {port}: expected 0 (any free port) to {MAX_PORT}")
        self.node, self.host, self.requested_port = node, host, port
        self.token = read_token(token)
        self.admission = Admission(HostPolicy(allow_hosts, server="Foxglove server"),
                                   self.token, allow_origins)
        self.context = foxglove.Context()
        self.log_limiter = limit_client_lines()
        self.relays = Relays(linger)
        self.bridge = Bridge(node, self.context, self.relays, poll=poll)
        self._sdk: WebSocketServer | None = None
        self.gate: Gate | None = None

    @property
    def port(self) -> int:
        """The port clients connect to (the one chosen when asked for 0), once started."""
        return self.gate.port if self.gate is not None else self.requested_port

    @property
    def on_loopback(self) -> bool:
        """Whether the server listens on this machine's loopback only."""
        return is_loopback(self.host)

    def url(self) -> str:
        """The address to open in Foxglove."""
        host = self.host if self.host not in ("0.0.0.0", "::", "") else "HOST"
        host = f"[{host}]" if ":" in host else host
        return f"ws://{host}:{self.port}"

    def start(self) -> None:
        """Start serving; FoxgloveError when the port is taken or a token is missing."""
        try:
            check_binding(self.host, self.token)
        except AdmissionError as exc:
            raise FoxgloveError(str(exc)) from None
        self._sdk = foxglove.start_server(name="cyborg", host="127.0.0.1",
                                          port=0, context=self.context,
                                          server_listener=self.relays)
        self.gate = Gate(self.host, self.requested_port, self._sdk.port, self.admission,
                         closed=self.log_limiter.client_gone,
                         housekeeping=self.log_limiter.sweep)
        try:
            self.gate.start()
        except GateError as exc:
            self._sdk.stop()
            self._sdk = None
            raise FoxgloveError(str(exc)) from None
        self.bridge.start()

    def stop(self) -> None:
        """Stop serving: channels withdrawn, bus subscriptions ended, clients disconnected."""
        self.bridge.stop()
        if self.gate is not None:
            self.gate.stop()
        if self._sdk is not None:
            self._sdk.stop()
            self._sdk = None
        self.log_limiter.flush()

    def exposure(self) -> str | None:
        """Where a server listening beyond loopback is reachable, and how; None on loopback."""
        if self.on_loopback:
            return None
        return (f"reachable from other machines at {self.url()} with the token "
                "(?token=...); without it, only from this machine")
