"""One browser connected to the monitor: what it watches, what it may do, its outgoing queue.

Messages to a browser go through a bounded queue drained by a writer task, so a slow browser
never holds up the others (or the tree). When its queue overflows the queue is emptied and the
client is marked for a *resync*: the writer then sends a fresh structure and snapshot, which
replace everything the dropped deltas would have told it.
"""

from __future__ import annotations

import asyncio
import json
from typing import Any

from starlette.websockets import WebSocket

QUEUE_LIMIT = 256
RESYNC = "\x00resync"


class Client:
    """A connected page."""

    def __init__(self, number: int, websocket: WebSocket, *, may_control: bool) -> None:
        self.number = number
        """Unique among this monitor's connections; the control seat knows clients by it."""
        self.websocket = websocket
        self.may_control = may_control
        """Loopback, or the right token: this client may take the control seat."""
        self.watching: str | None = None
        self.shown: tuple[str, str] | None = None
        """(namespace, structure version) of the tree the page draws now. A page keeps only
        the structure it draws, so any other tree, even one it was sent before, is sent
        again; deltas go only to a page that shows their tree."""
        self.queue: asyncio.Queue[str] = asyncio.Queue(QUEUE_LIMIT)
        self.dropped = 0
        self.sent = 0

    @property
    def host(self) -> str | None:
        client = self.websocket.client
        return client.host if client is not None else None

    def send(self, message: dict[str, Any] | str) -> None:
        """Queue a message (a dict, or JSON text shared between clients)."""
        text = message if isinstance(message, str) else json.dumps(message,
                                                                   separators=(",", ":"))
        try:
            self.queue.put_nowait(text)
        except asyncio.QueueFull:
            self.dropped += self.queue.qsize()
            while not self.queue.empty():
                self.queue.get_nowait()
            self.queue.put_nowait(RESYNC)

    async def next_message(self) -> str:
        return await self.queue.get()
