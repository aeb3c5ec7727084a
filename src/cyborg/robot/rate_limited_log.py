"""Log a failure that repeats every tick once per interval, and say how often it came meanwhile.

A behaviour node that fails at once is ticked again at once: a Repeater over a MoveTo whose
robot is gone fails ten times a second, and a warning per failure buries everything else in the
log (727 warnings in 75 s). :class:`RateLimitedLog` shows the first of a kind at once, counts
the ones that follow, and shows the next one after ``interval`` seconds with the count::

    limited = RateLimitedLog(logging.getLogger("cyborg.robot"))
    limited.warning(("MoveTo failed", node.uid), "MoveTo %s failed: %s", location, reason)
    # MoveTo room1 failed: no action server
    # ... 10 s later:
    # MoveTo room1 failed: no action server [99 more like this in the last 10 s]

A *kind* is the ``key`` the caller gives (any hashable value): the same key means "the same
failure again", whatever the details in the message. Keep keys few and stable (a reason and a
node id, not a message with numbers in it); the table of keys is bounded all the same.

The interval is in wall-clock seconds by default — a log is read in wall time, and a
simulation running 20 times faster than real time should not log 20 times as much; pass
``clock`` to count in other seconds (tests do). Nothing is logged when the repeats stop: the
count travels with the next message of its kind.
"""

from __future__ import annotations

import logging
import math
import threading
import time
from collections.abc import Callable, Hashable

INTERVAL = 10.0
"""Seconds between two messages of one kind, by default."""
MAX_KEYS = 1024
"""Kinds remembered at once, by default; the longest quiet are forgotten first."""


class RateLimitedLog:
    """At most one message per kind (``key``) per ``interval`` seconds on ``logger``."""

    def __init__(self, logger: logging.Logger, interval: float = INTERVAL, *,
                 clock: Callable[[], float] = time.monotonic, max_keys: int = MAX_KEYS) -> None:
        if not (math.isfinite(interval) and interval > 0):
            raise ValueError(f"interval must be a positive number of seconds, not {interval}")
        self.logger, self.interval, self.clock = logger, interval, clock
        self.max_keys = max(1, max_keys)
        self._kinds: dict[Hashable, tuple[float, int]] = {}  # key -> (last shown, left out)
        self._lock = threading.Lock()

    def __len__(self) -> int:
        return len(self._kinds)

    def log(self, level: int, key: Hashable, message: str, *args: object) -> bool:
        """Logs ``message % args`` at ``level``, or only counts it if its kind is too recent.

        It is counted instead when one of kind ``key`` was logged less than ``interval`` seconds
        ago. True when it was logged. Safe to call from any thread.
        """
        now = self.clock()
        with self._lock:
            shown, left_out = self._kinds.get(key, (-math.inf, 0))
            if now - shown < self.interval:
                self._kinds[key] = (shown, left_out + 1)
                return False
            if key not in self._kinds and len(self._kinds) >= self.max_keys:
                self._forget(now)
            self._kinds[key] = (now, 0)
        if left_out:
            text = message if args else message.replace("%", "%%")
            self.logger.log(level, f"{text} [%d more like this in the last %.0f s]", *args,
                            left_out, now - shown)
        else:
            self.logger.log(level, message, *args)
        return True

    def warning(self, key: Hashable, message: str, *args: object) -> bool:
        """:meth:`log` at WARNING level; True when it was logged."""
        return self.log(logging.WARNING, key, message, *args)

    def info(self, key: Hashable, message: str, *args: object) -> bool:
        """:meth:`log` at INFO level; True when it was logged."""
        return self.log(logging.INFO, key, message, *args)

    def _forget(self, now: float) -> None:
        """Make room: drop the kinds quiet for an interval, or else the older half."""
        quiet = [key for key, (shown, _) in self._kinds.items() if now - shown >= self.interval]
        if not quiet:
            by_age = sorted(self._kinds, key=lambda key: self._kinds[key][0])
            quiet = by_age[:max(1, len(by_age) // 2)]
        for key in quiet:
            del self._kinds[key]
