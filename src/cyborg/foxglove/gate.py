"""The gate in front of the Foxglove server: checks each handshake, then passes frames through.

foxglove-sdk's server cannot look at a handshake's headers, so it listens on a free loopback
port of its own and the gate listens where clients connect (``host:port``). For each
connection the gate reads the handshake (at most :data:`~cyborg.foxglove.admission.
HANDSHAKE_LIMIT` bytes, within :data:`HANDSHAKE_TIMEOUT` seconds), asks the
:class:`~cyborg.foxglove.admission.Admission` rules, answers ``403`` with the reason to a
refused one, and otherwise connects to the server and copies the connection's frames both ways
until either side closes, unchanged but for two things: a subscription the server refused for a
channel it had only just advertised is sent again, and message data a slow client cannot take
is dropped past a bound (:mod:`cyborg.foxglove.resubscribe`). It runs an asyncio loop on a
thread of its own.

The SDK's server accepts only the subprotocol ``foxglove.sdk.v1``; clients written before it
(older Foxglove Studio and Lichtblick releases, roslibjs-foxglove) offer only
``foxglove.websocket.v1``, whose messages are the same. For those the gate asks the server for
``foxglove.sdk.v1`` and answers the client with the name it offered (:data:`LEGACY`).
"""

from __future__ import annotations

import asyncio
import contextlib
import errno
import logging
import re
import socket
import threading
from collections.abc import Callable

from cyborg.foxglove.admission import HANDSHAKE_LIMIT, Admission, is_loopback, parse_handshake
from cyborg.foxglove.resubscribe import BACKLOG, STALL, Resubscriber

log = logging.getLogger("cyborg.foxglove")

HANDSHAKE_TIMEOUT = 10.0
"""Seconds a client has to send its handshake."""
HOUSEKEEPING = 1.0
"""Seconds between calls of the gate's ``housekeeping``."""
CURRENT = b"foxglove.sdk.v1"
"""The subprotocol the SDK's server requires."""
LEGACY = b"foxglove.websocket.v1"
"""The subprotocol older clients offer, translated to :data:`CURRENT` and back."""
_PROTOCOL_LINE = re.compile(rb"(?im)^(sec-websocket-protocol:)[^\r\n]*")


class GateError(RuntimeError):
    """The gate cannot listen (say, the port is in use); the message says what to do."""


class Gate:
    """Listens on ``host:port`` and lets admitted connections through to ``upstream_port``.

    ``closed`` is told the address the server knew a connection by (``127.0.0.1:PORT``, as
    the SDK logs it) when the connection ends; ``housekeeping`` runs every
    :data:`HOUSEKEEPING` seconds on the gate's thread.
    """

    def __init__(self, host: str, port: int, upstream_port: int, admission: Admission, *,
                 closed: Callable[[str], None] | None = None,
                 housekeeping: Callable[[], None] | None = None) -> None:
        self.host, self.requested_port = host, port
        self.upstream_port, self.admission = upstream_port, admission
        self.closed, self.housekeeping = closed, housekeeping
        self.port = port
        """The port listened on (the one chosen when ``port`` was 0), once started."""
        self.refused = 0
        """Handshakes refused so far."""
        self._loop = asyncio.new_event_loop()
        self._thread = threading.Thread(target=self._loop.run_forever, daemon=True,
                                        name="cyborg-foxglove-gate")
        self._server: asyncio.Server | None = None

    def start(self) -> None:
        """Listen; GateError when the port is taken or the address is not this machine's."""
        family = socket.AF_INET6 if ":" in self.host else socket.AF_INET
        try:
            listener = socket.create_server((self.host, self.requested_port), family=family)
        except OSError as exc:
            if exc.errno == errno.EADDRINUSE:
                raise GateError(f"port {self.requested_port} on {self.host} is in use (another "
                                "Foxglove server?); choose another with --port, or 0 for any "
                                "free port") from None
            raise GateError(f"cannot listen on {self.host}:{self.requested_port}: "
                            f"{exc.strerror}") from None
        self.port = listener.getsockname()[1]
        self._thread.start()
        self._server = asyncio.run_coroutine_threadsafe(
            asyncio.start_server(self._handle, sock=listener, limit=HANDSHAKE_LIMIT),
            self._loop).result()
        if self.housekeeping is not None:
            self._loop.call_soon_threadsafe(self._keep_house)

    def _keep_house(self) -> None:
        """Runs ``housekeeping`` (its errors logged), then again in :data:`HOUSEKEEPING` s."""
        try:
            if self.housekeeping is not None:
                self.housekeeping()
        except Exception:
            log.exception("the Foxglove gate's housekeeping failed")
        self._loop.call_later(HOUSEKEEPING, self._keep_house)

    def stop(self) -> None:
        """Stop listening and drop the connections."""
        if not self._thread.is_alive():
            return
        server = self._server

        async def close() -> None:
            if server is not None:
                server.close()
            for task in asyncio.all_tasks():
                if task is not asyncio.current_task():
                    task.cancel()
        with contextlib.suppress(Exception):
            asyncio.run_coroutine_threadsafe(close(), self._loop).result(5)
        self._loop.call_soon_threadsafe(self._loop.stop)
        self._thread.join(5)

    async def _handle(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        peer = writer.get_extra_info("peername")
        try:
            head = await asyncio.wait_for(reader.readuntil(b"\r\n\r\n"), HANDSHAKE_TIMEOUT)
            handshake = parse_handshake(head[:-4])
            refusal = self.admission.refusal(
                handshake, peer_loopback=bool(peer) and is_loopback(str(peer[0])))
        except (asyncio.IncompleteReadError, asyncio.LimitOverrunError, TimeoutError,
                ValueError, ConnectionError) as exc:
            await _answer(writer, f"400: not a WebSocket handshake ({type(exc).__name__})\n",
                          "400 Bad Request")
            return
        if refusal is not None:
            self.refused += 1
            log.warning("refused a Foxglove connection from %s: %s", peer, refusal.strip())
            await _answer(writer, refusal, "403 Forbidden")
            return
        try:
            upstream_reader, upstream_writer = await asyncio.open_connection(
                "127.0.0.1", self.upstream_port)
        except OSError:
            await _answer(writer, "503: the Foxglove server is not running\n",
                          "503 Service Unavailable")
            return
        offered = {name.strip().encode() for name in
                   handshake.headers.get("sec-websocket-protocol", "").split(",")}
        legacy = LEGACY in offered and CURRENT not in offered
        upstream_writer.write(_PROTOCOL_LINE.sub(rb"\1 " + CURRENT, head) if legacy else head)
        if legacy:
            try:
                answer = await asyncio.wait_for(upstream_reader.readuntil(b"\r\n\r\n"),
                                                HANDSHAKE_TIMEOUT)
            except (asyncio.IncompleteReadError, asyncio.LimitOverrunError, TimeoutError):
                writer.close()
                upstream_writer.close()
                return
            writer.write(_PROTOCOL_LINE.sub(rb"\1 " + LEGACY, answer))
        known_as = upstream_writer.get_extra_info("sockname")
        copy = Resubscriber()
        try:
            await copy.run((reader, writer), (upstream_reader, upstream_writer))
        finally:
            if copy.dropped:
                log.warning("Foxglove client %s was slower than its data: %d messages were "
                            "not sent to it (more than %d MiB waited)", peer, copy.dropped,
                            BACKLOG // (1024 * 1024))
            if copy.stalled:
                log.warning("Foxglove client %s took nothing for %.0f s with %d MiB waiting "
                            "for it: disconnected", peer, STALL, 2 * BACKLOG // (1024 * 1024))
            if self.closed is not None and known_as:
                self.closed(f"{known_as[0]}:{known_as[1]}")


async def _answer(writer: asyncio.StreamWriter, text: str, status: str) -> None:
    """An HTTP answer with ``text`` as its body, then close."""
    body = text.encode("utf-8")
    writer.write(f"HTTP/1.1 {status}\r\nContent-Type: text/plain; charset=utf-8\r\n"
                 f"Content-Length: {len(body)}\r\nConnection: close\r\n\r\n".encode() + body)
    with contextlib.suppress(ConnectionError, OSError):
        await writer.drain()
    writer.close()
