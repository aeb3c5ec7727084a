"""The newest state of each thing the pages follow: sent when it changed, at most so often.

The monitor's links (:mod:`~cyborg.monitor.mode_link`, :mod:`~cyborg.monitor.player_link`,
:mod:`~cyborg.monitor.service_link`) each hear of changes on the bus's threads and tell the
pages on the web server's event loop. They share this:

* :meth:`LatestState.notify` may be called from any thread, as often as the bus likes: the
  changes of one key that come before the loop has looked at the first are one change;
* :meth:`LatestState.changed` (on the loop) sends the key's text as it is *then* — so what a
  page gets is always the newest state, never a queue of old ones — unless it is the text sent
  last; and no key is sent twice within ``interval`` seconds: a change inside the interval is
  sent once the interval has passed (the newest then);
* ``text_of(key)`` makes the text (None: nothing to send), ``deliver(key, text)`` hands it to
  the pages that want it, and ``on_change(key)``, if given, sees every change first (the
  player link notices a jump back in time there, however quickly the sends follow).

    state = LatestState(0.25, lambda ns: json.dumps(message(ns)), deliver)
    state.attach(loop)           # from the server's start
    state.notify("/cyborg/bt")   # from a bus thread
"""

from __future__ import annotations

import asyncio
import contextlib
import math
import time
from collections.abc import Callable, Hashable
from typing import Generic, TypeVar

Key = TypeVar("Key", bound=Hashable)


class LatestState(Generic[Key]):
    """Sends each key's newest text when it changed, at most once per ``interval`` seconds."""

    def __init__(self, interval: float, text_of: Callable[[Key], str | None],
                 deliver: Callable[[Key, str], None],
                 on_change: Callable[[Key], None] | None = None) -> None:
        self.interval = interval
        self._text_of, self._deliver, self._on_change = text_of, deliver, on_change
        self._loop: asyncio.AbstractEventLoop | None = None
        self._pending: set[Key] = set()
        """Keys whose change was handed to the loop and not yet looked at."""
        self._later: set[Key] = set()
        """Keys with a send waiting for the interval to pass."""
        self._sent: dict[Key, str] = {}
        self._sent_at: dict[Key, float] = {}
        self.sends = 0
        """How many texts went to :meth:`deliver` (each counted once, however many pages)."""

    def attach(self, loop: asyncio.AbstractEventLoop) -> None:
        """Binds to the server's event loop; :meth:`notify` drops changes until then."""
        self._loop = loop

    def detach(self) -> None:
        """Lets go of the event loop as the server stops: changes are dropped from now on."""
        self._loop = None

    def notify(self, key: Key) -> None:
        """Called from any thread when what ``key`` names changed."""
        loop = self._loop
        if loop is None or loop.is_closed() or key in self._pending:
            return
        self._pending.add(key)
        with contextlib.suppress(RuntimeError):  # the loop closed meanwhile
            loop.call_soon_threadsafe(self.changed, key)

    def changed(self, key: Key) -> None:
        """On the loop: ``key`` changed; its text goes out now or once the interval passed."""
        self._pending.discard(key)
        if self._on_change is not None:
            self._on_change(key)
        self.send_soon(key)

    def send_soon(self, key: Key) -> None:
        """On the loop: ``key``'s text goes out now, or once the interval has passed.

        As :meth:`changed` without ``on_change``: for a state that changed here, not on the bus.
        """
        wait = self._sent_at.get(key, -math.inf) + self.interval - time.monotonic()
        if wait > 0:
            if key not in self._later and self._loop is not None:
                self._later.add(key)
                self._loop.call_later(wait, self._due, key)
            return
        self._send(key)

    def sent(self, key: Key) -> str | None:
        """The text last sent for ``key`` (None: none, or forgotten)."""
        return self._sent.get(key)

    def forget(self, key: Key) -> None:
        """Lets go of what was sent for ``key``: its next text goes out whatever it is."""
        self._sent.pop(key, None)
        self._sent_at.pop(key, None)

    def _due(self, key: Key) -> None:
        self._later.discard(key)
        self._send(key)

    def _send(self, key: Key) -> None:
        text = self._text_of(key)
        if text is None or text == self._sent.get(key):
            return
        self._sent[key], self._sent_at[key] = text, time.monotonic()
        self.sends += 1
        self._deliver(key, text)
