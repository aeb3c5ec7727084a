"""What the page gets of a runner's ``services`` message: checked, clamped, small.

A tree runner publishes the states of the services on its composites as
``cyborg_msgs/ServiceStates`` (:data:`cyborg.interfaces.tree_runner.SERVICE_STATES`). Anyone on
the bus may publish on that topic, so :func:`page_services` reads it as hostile input, against
the structure the monitor holds for that runner:

* an entry whose composite the structure does not know (a message from before a reload, or
  made up) is dropped, and so is one past :data:`MAX_SERVICES`;
* names, keys, values and errors are cut to :data:`NAME_LIMIT`, :data:`VALUE_LIMIT` and
  :data:`ERROR_LIMIT` characters (ending in ``…``), at most :data:`MAX_WROTE` keys per service;
* times are ``builtin_interfaces/Time`` (whole numbers: never NaN); a nanosecond count past a
  second is clamped to the second's last nanosecond. ``last`` is ``None`` for a service that
  never ran (``runs`` 0).

The result is the page's ``services`` message: ``{"t": "services", "ns", "v" (the structure's
version), "tree" (its tree_id), "time" (s, the tree's clock when the states were taken), "s":
[{"id", "name", "active", "runs", "last" (s or null), "wrote": [[key, value], ...],
"error"}], "dropped"}``, ``dropped`` counting the entries left out.
"""

from __future__ import annotations

from typing import Any

from cyborg.monitor.tree_state import TreeState

MAX_SERVICES = 512
"""Most services a page is told of, per tree."""
MAX_WROTE = 32
"""Most written keys a page is told of, per service."""
NAME_LIMIT = 100
"""Longest service name, written key or tree id, in characters."""
VALUE_LIMIT = 60
"""Longest written value, in characters (the runner's own are 60 at most)."""
ERROR_LIMIT = 300
"""Longest error text, in characters."""
_NANOSECONDS = 1_000_000_000


def clip(text: Any, limit: int) -> str:
    """``text`` as a string of at most ``limit`` characters, cut ones ending in ``…``."""
    shown = str(text)
    return shown if len(shown) <= limit else shown[:limit - 1] + "…"


def seconds_of(stamp: Any) -> float:
    """A ``builtin_interfaces/Time`` in seconds, to the microsecond below.

    A nanosecond count past the second is clamped to the second's last nanosecond.
    """
    nanoseconds = min(max(int(stamp.nanosec), 0), _NANOSECONDS - 1)
    return int(stamp.sec) + (nanoseconds // 1000) / 1e6


def page_services(namespace: str, message: Any, state: TreeState) -> dict[str, Any]:
    """The page's ``services`` message for ``message`` read against ``state``; see above."""
    known = state.index_of
    entries: list[dict[str, Any]] = []
    dropped = 0
    for entry in message.services:
        composite = str(entry.composite)
        if composite not in known or len(entries) >= MAX_SERVICES:
            dropped += 1
            continue
        runs = int(entry.runs)
        entries.append({
            "id": composite,
            "name": clip(entry.service, NAME_LIMIT),
            "active": bool(entry.active),
            "runs": runs,
            "last": seconds_of(entry.last_run) if runs > 0 else None,
            "wrote": [[clip(pair.key, NAME_LIMIT), clip(pair.value, VALUE_LIMIT)]
                      for pair in entry.wrote[:MAX_WROTE]],
            "error": clip(entry.error, ERROR_LIMIT),
        })
    return {"t": "services", "ns": namespace, "v": state.version,
            "tree": clip(message.tree_id, NAME_LIMIT), "time": seconds_of(message.stamp),
            "s": entries, "dropped": dropped}
