"""One browser connected to the monitor: what it watches, what it may do, its outgoing queue.

Messages to a browser go through a queue drained by a writer task, so a slow browser never
holds up the others (or the tree). The queue is bounded twice: in messages
(:data:`QUEUE_LIMIT`) and in characters (:data:`QUEUE_BYTES`, since one structure of a large tree
weighs as much as thousands of deltas). When either overflows the queue is emptied and the
client is marked for a *resync*: the writer then sends a fresh structure and snapshot, which
replace everything the dropped messages would have told it. One message may exceed the
character bound only when the queue is empty (the structure of a tree near the loader's node
cap), and never :data:`MESSAGE_CHARACTERS`: a larger one is not sent, and said so in the log.
"""

from __future__ import annotations

import asyncio
import json
import logging
from typing import Any

from starlette.websockets import WebSocket

from cyborg.monitor.limits import Bucket, Limits

log = logging.getLogger("cyborg.monitor")

QUEUE_LIMIT = 256
QUEUE_BYTES = 8 << 20
"""Characters a client's queue may hold (8 Mi: a few structures of the largest trees)."""
MESSAGE_CHARACTERS = 24 << 20
"""Characters one message may have (the structure of a 100,000-node tree has some 16.5 Mi)."""
RESYNC = "\x00resync"


class Client:
    """A connected page."""

    def __init__(self, number: int, websocket: WebSocket, *, may_control: bool,
                 limits: Limits | None = None) -> None:
        self.number = number
        """Unique among this monitor's connections; the control seat knows clients by it."""
        self.websocket = websocket
        self.may_control = may_control
        """Loopback with the page's own origin, or the right token: this client may take the
        control seat."""
        self.watching: str | None = None
        self.shown: tuple[str, str] | None = None
        """(namespace, structure version) of the tree the page draws now. A page keeps only
        the structure it draws, so any other tree, even one it was sent before, is sent
        again; deltas go only to a page that shows their tree."""
        self.asked: set[str] = set()
        self.map_view = False
        """The page shows the map: it gets the robots' state (:mod:`cyborg.monitor.robot_hub`)."""
        """Namespaces no runner was in that this page watched (capped per connection)."""
        limits = limits or Limits()
        self.bucket = Bucket(limits.rate, limits.burst)
        """Paces the messages this page sends."""
        self.received = 0
        """Messages received from the page: the number an error message refers to."""
        self.queue: asyncio.Queue[str] = asyncio.Queue(QUEUE_LIMIT)
        self.queued_bytes = 0
        self.dropped = 0
        self.sent = 0

    @property
    def host(self) -> str | None:
        """The peer's address as the server saw it; None when the transport did not say."""
        client = self.websocket.client
        return client.host if client is not None else None

    def send(self, message: dict[str, Any] | str) -> None:
        """Queue a message (a dict, or JSON text shared between clients)."""
        text = message if isinstance(message, str) else json.dumps(message,
                                                                   separators=(",", ":"))
        if len(text) > MESSAGE_CHARACTERS:
            self.dropped += 1
            log.warning("page %d: a message of %s characters (%s) was not sent: past the "
                        "%s a message may have", self.number, f"{len(text):,}", text[:40],
                        f"{MESSAGE_CHARACTERS:,}")
            return
        if self.queued_bytes + len(text) > QUEUE_BYTES and not self.queue.empty():
            self._overflow()
            return
        try:
            self.queue.put_nowait(text)
        except asyncio.QueueFull:
            self._overflow()
            return
        self.queued_bytes += len(text)

    def _overflow(self) -> None:
        self.dropped += self.queue.qsize()
        while not self.queue.empty():
            self.queue.get_nowait()
        self.queued_bytes = 0
        self.queue.put_nowait(RESYNC)

    async def next_message(self) -> str:
        """Waits for the next queued message, for the writer task; :data:`RESYNC` asks for one."""
        text = await self.queue.get()
        self.queued_bytes = max(0, self.queued_bytes - len(text))
        return text
