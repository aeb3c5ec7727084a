"""foxglove-sdk's log lines about what a client sent, one per client and kind per period.

The SDK's server (Rust) logs through Python's :mod:`logging`, under loggers named after its
modules. For each bad message a client sends it logs a line on :data:`SDK_CLIENT_LOGGER`, an
``ERROR`` for a subscription to a channel that does not exist (``Client 127.0.0.1:38430
attempted to subscribe to unknown channel: 7``): one client wrote 77,100 such lines in seconds.
The :class:`RepeatLimiter` (a :class:`logging.Filter` on that logger, :func:`install`) passes
the first line of each :data:`KINDS` per client and :data:`PERIOD`, counts the rest, and then
says how many there were::

    Client 127.0.0.1:38430: 77099 more like this in the last 3.2 s (subscribing to unknown channels)

when the period ends (:meth:`RepeatLimiter.sweep`, which the next line and the gate's
housekeeping call), when the client leaves (:meth:`RepeatLimiter.client_gone`) or when the
server stops (:meth:`RepeatLimiter.flush`). Every other line passes as it is. At most
:data:`TRACKED` clients and kinds are counted apart in one period; further ones share one count
per kind (``Other clients: ...``), so a flood of connections is bounded too.
"""

from __future__ import annotations

import logging
import re
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass

SDK_CLIENT_LOGGER = "foxglove.websocket.connected_client"
"""The SDK's logger for what happens on one client's connection."""
PERIOD = 10.0
"""Seconds in which one line of each kind per client passes; the rest are counted."""
TRACKED = 64
"""Clients and kinds counted apart in one period; the others share one count per kind."""
KINDS: tuple[tuple[str, re.Pattern[str]], ...] = (
    ("subscribing to unknown channels",
     re.compile(r"Client (?P<client>\S+) attempted to subscribe to unknown channel: \d+")),
    ("invalid messages", re.compile(r"Invalid message from (?P<client>\S+): ")),
    ("messages for unknown channels", re.compile(r"Received message for unknown channel: \d+")),
    ("errors sent to the client", re.compile(r"Sending error to client (?P<client>\S+): ")),
)
"""The lines a client causes at will: what they are about, and how to know them."""
SUMMARY = "cyborg_summary"
"""The attribute that marks the limiter's own summary records, which always pass."""
_OTHERS = "\0others"
"""The client under which lines beyond :data:`TRACKED` are counted."""


def classify(message: str) -> tuple[str, str] | None:
    """The kind of a line a client causes and the client it names ("" if none); None if other."""
    for kind, pattern in KINDS:
        match = pattern.match(message)
        if match is not None:
            client = match.groupdict().get("client") or ""
            return kind, client
    return None


@dataclass
class _Window:
    """One client's lines of one kind in the current period."""

    start: float
    level: int
    more: int = 0


class RepeatLimiter(logging.Filter):
    """Passes the first line of each kind per client and ``period``; counts and sums up the rest.

    Thread-safe: the SDK logs from its own threads. ``clock`` gives seconds (monotonic).
    """

    def __init__(self, period: float = PERIOD, tracked: int = TRACKED,
                 clock: Callable[[], float] = time.monotonic) -> None:
        super().__init__()
        self.period, self.tracked, self.clock = period, tracked, clock
        self.suppressed = 0
        """Lines held back so far (each counted in a summary)."""
        self._lock = threading.Lock()
        self._windows: dict[tuple[str, str], _Window] = {}  # (client, kind) -> its window
        self._next_sweep = float("inf")

    def filter(self, record: logging.LogRecord) -> bool:
        """Whether ``record`` is logged: the first of its kind for its client this period."""
        if getattr(record, SUMMARY, False):
            return True
        found = classify(record.getMessage())
        if found is None:
            return True
        kind, client = found
        now = self.clock()
        with self._lock:
            due = self._take(lambda window: now - window.start >= self.period, now)
            key = (client, kind)
            if key not in self._windows and len(self._windows) >= self.tracked:
                key = (_OTHERS, kind)
            window = self._windows.get(key)
            if window is None:
                self._windows[key] = _Window(now, record.levelno)
                self._next_sweep = min(self._next_sweep, now + self.period)
            else:
                window.more += 1
                self.suppressed += 1
        self._say(due, now)
        return window is None

    def sweep(self) -> None:
        """Sum up the periods that have ended."""
        now = self.clock()
        with self._lock:
            due = self._take(lambda window: now - window.start >= self.period, now)
        self._say(due, now)

    def client_gone(self, client: str) -> None:
        """Sum up the lines of ``client`` (``host:port`` as the SDK names it), which left."""
        now = self.clock()
        with self._lock:
            due = self._take(lambda window: True, now, client)
        self._say(due, now)

    def flush(self) -> None:
        """Sum up every count now (the server stops)."""
        now = self.clock()
        with self._lock:
            due = self._take(lambda window: True, now, force=True)
        self._say(due, now)

    def tracked_now(self) -> int:
        """Clients and kinds being counted now (at most :attr:`tracked` plus one per kind)."""
        with self._lock:
            return len(self._windows)

    def _take(self, ended: Callable[[_Window], bool], now: float, client: str | None = None,
              *, force: bool = False) -> list[tuple[str, str, _Window]]:
        """Removes and returns the windows that ``ended`` (of ``client`` only, if given)."""
        if client is None and not force and now < self._next_sweep:
            return []
        taken = [(key, window) for key, window in self._windows.items()
                 if (client is None or key[0] == client) and ended(window)]
        for key, _ in taken:
            del self._windows[key]
        if client is None:
            self._next_sweep = min((window.start + self.period
                                    for window in self._windows.values()), default=float("inf"))
        return [(key[0], key[1], window) for key, window in taken]

    def _say(self, due: list[tuple[str, str, _Window]], now: float) -> None:
        """Logs a summary line for each window in ``due`` that held lines back."""
        logger = logging.getLogger(SDK_CLIENT_LOGGER)
        for client, kind, window in due:
            if not window.more:
                continue
            who = ("Other clients: " if client == _OTHERS
                   else f"Client {client}: " if client else "")
            logger.log(window.level, "%s%d more like this in the last %.1f s (%s)", who,
                       window.more, now - window.start, kind, extra={SUMMARY: True})


LIMITER = RepeatLimiter()
"""The process's limiter: the SDK's loggers are the process's."""


def install() -> RepeatLimiter:
    """Puts :data:`LIMITER` on the SDK's client logger (once) and returns it."""
    logger = logging.getLogger(SDK_CLIENT_LOGGER)
    if LIMITER not in logger.filters:
        logger.addFilter(LIMITER)
    return LIMITER
