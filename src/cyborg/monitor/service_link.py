"""The services on each tree's composites, from the runner to the pages that watch the tree.

Owned by :class:`~cyborg.monitor.hub.Hub`; everything here runs on the web server's event loop
except :meth:`ServiceLink.notify`, which the bus calls from its threads when a runner's
``services`` message came (:class:`~cyborg.monitor.source.TreeSource` keeps it).

* **To the pages:** the ``services`` message (:mod:`cyborg.monitor.service_wire`), read
  against the structure the monitor holds, goes to the pages watching that tree when it
  changed, at most once per :data:`SERVICES_INTERVAL` per tree (the newest goes out when the
  interval has passed); to a page that starts showing the tree, after its snapshot
  (:meth:`ServiceLink.send_to`). A tree whose runner never published services sends nothing.
* Ticks never wait for it: the runner already sends at most four a second, and the page's
  paint at tick rate never reads it (a badge changes only when a message comes).
"""

from __future__ import annotations

import asyncio
import json
from collections.abc import Collection, Mapping
from typing import Any

from cyborg.monitor.client import Client
from cyborg.monitor.latest_state import LatestState
from cyborg.monitor.source import TreeSource

SERVICES_INTERVAL = 0.25
"""Shortest time between two ``services`` messages of one tree (s): at most four a second."""


def _encode(message: dict[str, Any]) -> str:
    return json.dumps(message, separators=(",", ":"))


class ServiceLink:
    """Sends each tree's service states to its pages; see the module docstring.

    ``clients`` are the hub's pages and ``sources`` the trees it follows, by namespace.
    """

    def __init__(self, clients: Collection[Client], sources: Mapping[str, TreeSource]) -> None:
        self._clients, self._sources = clients, sources
        self._state = LatestState[str](SERVICES_INTERVAL, self._text, self._deliver)

    @property
    def messages(self) -> int:
        """How many ``services`` messages went to pages (each counted once, however many)."""
        return self._state.sends

    def attach(self, loop: asyncio.AbstractEventLoop) -> None:
        """Binds the link to the server's event loop; :meth:`notify` drops changes until then."""
        self._state.attach(loop)

    def notify(self, namespace: str) -> None:
        """Called from any thread when the runner under ``namespace`` sent its services."""
        self._state.notify(namespace)

    def send_to(self, client: Client, namespace: str) -> None:
        """Sends ``client`` the services of the tree under ``namespace`` as they are now."""
        source = self._sources.get(namespace)
        message = source.services_message() if source is not None else None
        if message is not None:
            client.send(message)

    def forget(self, namespace: str) -> None:
        """Lets go of what was kept for a tree the monitor no longer follows."""
        self._state.forget(namespace)

    def _text(self, namespace: str) -> str | None:
        source = self._sources.get(namespace)
        message = source.services_message() if source is not None else None
        return None if message is None else _encode(message)

    def _deliver(self, namespace: str, text: str) -> None:
        for client in self._clients:
            if client.watching == namespace:
                client.send(text)
