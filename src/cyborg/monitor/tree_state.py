"""What the monitor knows about one running tree, and what it sends browsers about it.

A :class:`TreeState` is built from one ``behavior_tree`` structure message and then fed the
runner's ``status`` messages (one per tick). It keeps, per node (by pre-order index):

* the last status the node returned and the tick it returned it in, so a view can show both
  *what ran this tick* and *what a node returned last time* (Groot2's ``IDLE_FROM_*``);
* tick-time statistics (count, last, mean, min, max, in milliseconds) and how often its status
  changed;
* a ring of recent ticks (the history timeline a browser scrubs through).

Browsers get the structure once per version, a full :meth:`snapshot` on connect, and then
:meth:`frame` deltas: only nodes whose *display code* changed. A display code is the status
number (0 = never ticked, 1 success, 2 failure, 3 running, 4 error) plus :data:`FRESH` when the
node was ticked in the latest tick. Deltas are idempotent ("node i shows code c"), so a snapshot
racing a delta does no harm; every message carries a ``seq`` and clients drop old ones.

The class does no I/O and is safe to use from two threads (the bus thread feeds it, the web
server reads it).
"""

from __future__ import annotations

import threading
from collections import deque
from dataclasses import dataclass
from typing import Any

import numpy as np
import xxhash

from cyborg.bt.outline import StructureOutline
from cyborg.bt.status import Status

FRESH = 8
"""Added to a node's status in a display code when the node ran in the latest tick."""

HISTORY_TICKS = 1200
"""Ticks kept for the history timeline (a minute at 20 Hz, two at the default 10 Hz)."""


def status_name(code: int) -> str:
    """``"success"`` for 1 and so on, as the engine names statuses; ``"?"`` for others."""
    try:
        return Status(code).label
    except ValueError:
        return "?"


@dataclass(frozen=True)
class TickEntry:
    """One tick, as kept in the history."""

    tick: int
    time: float
    duration: float
    root: int
    visited: np.ndarray
    """Node indices ticked, in completion order."""
    statuses: np.ndarray
    active: tuple[int, ...]

    def to_json(self) -> list[Any]:
        """``[tick, time (s), duration (ms), root status, visited, statuses, active]``."""
        return [self.tick, round(self.time, 4), round(self.duration * 1000.0, 4), self.root,
                self.visited.tolist(), self.statuses.tolist(), list(self.active)]


class TreeState:
    """One version of a running tree's structure plus everything seen since it arrived."""

    def __init__(self, text: str, *, history: int = HISTORY_TICKS) -> None:
        outline = StructureOutline.parse(text)
        self.text = text
        self.structure: dict[str, Any] = outline.structure
        self.version = xxhash.xxh64_hexdigest(text.encode())
        """Identifies the structure: same text, same version."""
        self.ids = outline.ids
        self.parents = outline.parents
        self.labels = outline.labels
        """Each node's label (its title with the properties filled in), else its name."""
        self.index_of = outline.index_of
        count = len(self.ids)
        self._lock = threading.Lock()
        self.status = np.zeros(count, np.uint8)
        self.last_tick = np.zeros(count, np.int64)
        self.since = np.zeros(count, np.float64)
        """Tree time at which each node's current status began."""
        self.changes = np.zeros(count, np.int64)
        self.calls = np.zeros(count, np.int64)
        self.total_ms = np.zeros(count, np.float64)
        self.min_ms = np.full(count, np.inf)
        self.max_ms = np.zeros(count, np.float64)
        self.last_ms = np.full(count, np.nan)
        self._timed = np.zeros(count, bool)  # timings changed since the last timing message
        self._shown = np.zeros(count, np.uint8)
        self.active: tuple[int, ...] = ()
        self._active_shown: tuple[int, ...] | None = None
        self.tick = 0
        self.time = 0.0
        self.duration = 0.0
        self.root_status = 0
        self.seq = 0
        self._header_seen = -1  # the tick the last frame reported
        self.ticks_seen = 0
        self.history: deque[TickEntry] = deque(maxlen=history)

    def __len__(self) -> int:
        return len(self.ids)

    # ------------------------------------------------------------------ feeding
    def apply_tick(self, tick: int, time: float, duration: float, root: int,
                   visited_ids: list[str], statuses: np.ndarray, durations: np.ndarray,
                   active_ids: list[str]) -> None:
        """Takes one ``status`` message, on the bus node's thread (durations in s).

        Ids the structure does not know are ignored (a message from before a reload).
        """
        index_of = self.index_of
        pairs = [(index_of.get(uid, -1), position) for position, uid in enumerate(visited_ids)]
        known = [(index, position) for index, position in pairs if index >= 0]
        indices = np.fromiter((index for index, _ in known), np.int64, len(known))
        positions = np.fromiter((position for _, position in known), np.int64, len(known))
        new_status = np.asarray(statuses, np.uint8)[positions] if len(statuses) else \
            np.zeros(len(known), np.uint8)
        active = tuple(index for index in (index_of.get(uid, -1) for uid in active_ids)
                       if index >= 0)
        with self._lock:
            changed = self.status[indices] != new_status
            self.changes[indices[changed]] += 1
            self.since[indices[changed]] = time
            self.status[indices] = new_status
            self.last_tick[indices] = tick
            if len(durations) == len(visited_ids) and len(known):
                milliseconds = np.asarray(durations, np.float64)[positions] * 1000.0
                timed = ~np.isnan(milliseconds)
                where, values = indices[timed], milliseconds[timed]
                np.add.at(self.calls, where, 1)
                np.add.at(self.total_ms, where, values)
                np.minimum.at(self.min_ms, where, values)
                np.maximum.at(self.max_ms, where, values)
                self.last_ms[where] = values
                self._timed[where] = True
            self.tick, self.time, self.duration, self.root_status = tick, time, duration, root
            self.active = active
            self.ticks_seen += 1
            self.history.append(TickEntry(tick, time, duration, root, indices.astype(np.int32),
                                          new_status, active))

    def apply_active(self, active_ids: list[str]) -> None:
        """Takes a ``behavior_tree_updates`` message: the active path, by node id.

        The runner sends it also when the tree is paused and no ticks come.
        """
        index_of = self.index_of
        with self._lock:
            self.active = tuple(index_of[uid] for uid in active_ids if uid in index_of)

    # ------------------------------------------------------------------ reading
    def _codes(self) -> np.ndarray:
        fresh = (self.last_tick == self.tick) & (self.tick > 0)
        codes: np.ndarray = self.status + fresh.astype(np.uint8) * FRESH
        return codes

    def snapshot(self) -> dict[str, Any]:
        """Everything a browser needs to draw the current state (after the structure)."""
        with self._lock:
            return {"t": "snapshot", "v": self.version, "seq": self.seq,
                    **self._header(), "codes": self._codes().tolist(),
                    "act": list(self.active)}

    def frame(self) -> dict[str, Any] | None:
        """The changes since the last frame, or None when nothing changed."""
        with self._lock:
            codes = self._codes()
            changed = np.flatnonzero(codes != self._shown)
            active = self.active if self.active != self._active_shown else None
            if not len(changed) and active is None and self._header_seen == self.tick:
                return None
            self._shown = codes
            self._active_shown = self.active
            self.seq += 1
            self._header_seen = self.tick
            pairs = np.empty(2 * len(changed), np.int64)
            pairs[0::2], pairs[1::2] = changed, codes[changed]
            message: dict[str, Any] = {"t": "tick", "v": self.version, "seq": self.seq,
                                       **self._header(), "ch": pairs.tolist()}
            if active is not None:
                message["act"] = list(active)
            return message

    def _header(self) -> dict[str, Any]:
        return {"tick": self.tick, "time": round(self.time, 4),
                "dur": round(self.duration * 1000.0, 4), "root": self.root_status}

    def timings(self, *, all_nodes: bool = False) -> list[list[float]]:
        """``[index, calls, last, mean, min, max (ms), status changes, since]`` rows.

        One row for each node whose timings changed since the last call without ``all_nodes``
        (or, with it, every timed node).
        """
        with self._lock:
            which = np.flatnonzero(self.calls > 0 if all_nodes else self._timed)
            if not all_nodes:  # a page's first full table leaves the others' deltas be
                self._timed[:] = False
            calls = self.calls[which]
            rows = np.column_stack([
                which, calls, self.last_ms[which], self.total_ms[which] / calls,
                self.min_ms[which], self.max_ms[which], self.changes[which],
                self.since[which]]).round(4)
        return [[int(row[0]), int(row[1]), *row[2:6].tolist(), int(row[6]), float(row[7])]
                for row in rows]

    def history_json(self) -> list[list[Any]]:
        """The kept ticks, oldest first (see :meth:`TickEntry.to_json`)."""
        with self._lock:
            entries = list(self.history)
        return [entry.to_json() for entry in entries]

    def running_label(self) -> str:
        """The label of the node running now: the deepest node of the active path, or "".

        The active path holds every node RUNNING after the latest tick, root first; the node
        that does the work is the deepest of them (a leaf, or a decorator whose child did not
        run). Where a parallel runs several branches, the first of the deepest (in pre-order)
        is named. "" when nothing runs (the tree is idle, or finished its tick).
        """
        with self._lock:
            active = self.active
        if not active:
            return ""
        depth: dict[int, int] = {}
        for index in active:  # root first: a node's active parent came before it
            depth[index] = depth.get(self.parents[index], -1) + 1
        deepest = max(active, key=lambda index: (depth[index], -index))
        return self.labels[deepest]

    def statuses_by_id(self) -> dict[str, str]:
        """Last status of every node that has run, by id (for exports)."""
        with self._lock:
            return {self.ids[index]: status_name(int(code))
                    for index, code in enumerate(self.status) if code}

    def active_ids(self) -> list[str]:
        """Ids of the nodes on the active path, in the runner's order (for exports)."""
        with self._lock:
            return [self.ids[index] for index in self.active]
