"""A followed robot's warnings for the pages: by kind, counted, told at most once a second.

Each :class:`~cyborg.monitor.robot_source.RobotSource` keeps a :class:`WarningLog`: the bus
threads add what a robot's messages did wrong (a NaN pose, a scan of the wrong length, an
object off the map ...), the hub tells the pages each kind as ``robot_warn`` with how often it
happened, no more than once per :data:`WARNING_INTERVAL` per kind.
"""

from __future__ import annotations

import threading
import time
from dataclasses import dataclass

WARNING_INTERVAL = 1.0
"""Shortest time between two warnings of one kind about one robot sent to the pages (s)."""


@dataclass
class _Warning:
    message: str
    count: int
    told: int = 0
    """The count the pages were last told."""
    told_at: float = -float("inf")


class WarningLog:
    """One robot's warnings by kind: the latest text of each, how often, what pages were told.

    Safe to use from several threads: the bus thread adds, the web server's loop reads.
    """

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._kinds: dict[str, _Warning] = {}

    def add(self, kind: str, message: str) -> None:
        """Counts one more warning of ``kind``; ``message`` becomes its latest text."""
        with self._lock:
            found = self._kinds.get(kind)
            if found is None:
                self._kinds[kind] = _Warning(message, 1)
            else:
                found.message, found.count = message, found.count + 1

    def due(self, now: float | None = None) -> list[tuple[str, str, int]]:
        """``(kind, message, count)`` of each kind the pages should hear of now; marks them told.

        A kind is due when it happened since the pages were last told, and that was at least
        :data:`WARNING_INTERVAL` s ago.
        """
        now = time.monotonic() if now is None else now
        due = []
        with self._lock:
            for kind, warning in self._kinds.items():
                if warning.count > warning.told and now - warning.told_at >= WARNING_INTERVAL:
                    warning.told, warning.told_at = warning.count, now
                    due.append((kind, warning.message, warning.count))
        return due

    def pending(self) -> bool:
        """Whether some warning has not been told yet (it may not be due yet)."""
        with self._lock:
            return any(warning.count > warning.told for warning in self._kinds.values())

    def latest(self) -> list[tuple[str, str, int]]:
        """``(kind, message, count)`` of every kind so far, for a page that starts to look."""
        with self._lock:
            return [(kind, warning.message, warning.count)
                    for kind, warning in self._kinds.items()]
