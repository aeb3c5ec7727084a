"""What one viewer may cost the monitor, and the checks that keep it there.

Anyone who can reach the page may watch, so watching must be cheap and bounded:

* **Trees followed.** Following a tree costs bus subscriptions and service clients (~0.4 MiB
  each). The monitor follows the trees it was started with, and a tree runner found on the bus
  while it is there or some page watches it; all pages watching a tree share one set of
  subscriptions. Watching a namespace no runner is in subscribes to nothing, and a connection
  may watch at most :attr:`Limits.namespaces_per_connection` such namespaces in its life.
* **Connections**: at most :attr:`Limits.connections_per_address` from one address, at most
  :attr:`Limits.connections` in all. The page that would be one too many is told so and closed.
* **Names**: a namespace is checked (:func:`check_namespace`) before it reaches the bus, where a
  wildcard such as ``/**`` is a key expression, not a name.
* **Messages**: at most :data:`MESSAGE_LIMIT` characters (the web server closes the connection
  on frames over :data:`FRAME_LIMIT` bytes), JSON nested at most :data:`DEPTH_LIMIT` levels
  (checked before parsing: Python's parser recurses), no NaN or infinities, and at most
  :attr:`Limits.rate` messages a second after a burst of :attr:`Limits.burst` (a token bucket).

A refusal is a :class:`MessageError` (a ``ValueError`` from :func:`check_namespace`, which
the commands turn into a :class:`~cyborg.monitor.refusal.RefusalError` naming ``ns``); the
server answers it as an ``error`` message that says which message and, where known, which
field and which character (see :mod:`cyborg.monitor.commands`).
"""

from __future__ import annotations

import json
import re
import time
from dataclasses import dataclass
from typing import Any

from cyborg.bt.json_text import too_deep
from cyborg.monitor.refusal import RefusalError

MESSAGE_LIMIT = 64 * 1024
"""Longest message a page may send, in characters (the page's own are under 1 KiB)."""
FRAME_LIMIT = 2 * MESSAGE_LIMIT
"""Longest WebSocket frame the web server reads, in bytes; longer ones close the connection
(code 1009)."""
BODY_LIMIT = 1 << 20
"""Longest request body (an export request), in bytes."""
DEPTH_LIMIT = 32
"""Deepest JSON nesting a message may have (the page's own have 3 levels)."""
NAMESPACE_LIMIT = 200
"""Longest namespace, in characters."""

_NAMESPACE = re.compile(r"^(?:/[A-Za-z][A-Za-z0-9_]*)+$")


@dataclass(frozen=True)
class Limits:
    """The monitor's limits for viewers; see the module docstring."""

    namespaces_per_connection: int = 16
    connections_per_address: int = 32
    connections: int = 256
    rate: float = 50.0
    """Messages per second a connection may send, on average."""
    burst: int = 200
    """Messages a connection may send at once before :attr:`rate` applies."""

    def refusal(self, hosts: list[str | None], host: str | None) -> str | None:
        """Why one more connection from ``host`` is refused beside ``hosts``' ones, or None."""
        if len(hosts) >= self.connections:
            return (f"the monitor has {self.connections} connections already; close "
                    "monitor pages you do not use")
        if hosts.count(host) >= self.connections_per_address:
            return (f"{self.connections_per_address} connections from {host} already; "
                    "close monitor pages you do not use")
        return None


class MessageError(RefusalError):
    """A message the monitor will not read; ``pos`` is the character where it went wrong."""

    def __init__(self, message: str, pos: int | None = None) -> None:
        super().__init__(message, pos=pos)


def check_namespace(value: Any) -> str:
    """``value`` if it is a namespace a tree runner can have; ``ValueError`` otherwise.

    A namespace is ``/`` and segments of letters, digits and ``_`` (each starting with a
    letter), at most :data:`NAMESPACE_LIMIT` characters. A single trailing ``/`` is dropped.
    """
    if not isinstance(value, str):
        raise ValueError(f"a namespace is a string such as /cyborg/bt, not {_short(value)}")
    if len(value) > NAMESPACE_LIMIT:
        raise ValueError(f"a namespace has at most {NAMESPACE_LIMIT} characters, not "
                         f"{len(value)}")
    name = value[:-1] if value.endswith("/") and len(value) > 1 else value
    if not _NAMESPACE.match(name):
        raise ValueError(f"{_short(value)} is not a namespace: expected / and names of "
                         "letters, digits and _ such as /cyborg/bt (no wildcards)")
    return name


def decode(text: str) -> Any:
    """The JSON value of a message, within :data:`MESSAGE_LIMIT` and :data:`DEPTH_LIMIT`.

    Raises :class:`MessageError` (with the character position where known) otherwise.
    """
    if len(text) > MESSAGE_LIMIT:
        raise MessageError(f"longer than {MESSAGE_LIMIT} characters ({len(text)})")
    _check_depth(text)
    try:
        return json.loads(text, parse_constant=_no_constant)
    except json.JSONDecodeError as exc:
        raise MessageError(f"not JSON: {exc}", exc.pos) from None
    except ValueError as exc:  # a number of more than 4,300 digits, NaN, Infinity
        raise MessageError(f"not usable JSON: {exc}") from None


def _check_depth(text: str) -> None:
    deep = too_deep(text, DEPTH_LIMIT)
    if deep is not None:
        raise MessageError(f"nested deeper than {DEPTH_LIMIT} levels", deep)


def _no_constant(name: str) -> Any:
    raise ValueError(f"{name} is not a number JSON allows")


def _short(value: Any, limit: int = 60) -> str:
    text = repr(value)
    return text if len(text) <= limit else text[:limit] + "…"


class Bucket:
    """A token bucket: at most ``burst`` messages at once, ``rate`` a second on average.

    :meth:`take` is True while the average stays under ``rate`` a second after a burst of
    ``burst``.
    """

    def __init__(self, rate: float, burst: int) -> None:
        self.rate, self.burst = rate, float(burst)
        self.tokens = float(burst)
        self.last = time.monotonic()

    def take(self, now: float | None = None) -> bool:
        """Whether one more message may go now (``time.monotonic()`` s by default); takes it."""
        now = time.monotonic() if now is None else now
        self.tokens = min(self.burst, self.tokens + (now - self.last) * self.rate)
        self.last = now
        if self.tokens < 1.0:
            return False
        self.tokens -= 1.0
        return True
