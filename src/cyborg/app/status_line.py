"""A one-line live view of a running tree: tick count, root status and active path.

On a terminal the line is redrawn in place (at most 10 times a second) and always fits it
(:func:`fit_status`): the tick and the root status stay, and a long active path is shortened
from the middle, keeping the root and the nodes running now. Into a pipe or file a new line,
in full, is written only when the root status or the active path changes, so logs stay short.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from typing import TextIO

from cyborg.app.progress import terminal_width
from cyborg.bt import Status, Tree
from cyborg.bt.snapshot import TickSnapshot

SEPARATOR, ELLIPSIS = " > ", "…"
"""What stands between two labels of the path, and for the labels left out."""


def fit_status(tick: int, status: Status, labels: Sequence[str], width: int) -> str:
    """The line of one tick, ``tick 42  RUNNING  Root tree > … > MoveTo``, in ``width`` columns.

    The tick number and the status are always there (with single spaces when the line is very
    narrow); the active path (root first) takes what room is left.
    """
    head = f"tick {tick:>6}  {status.name:<7}"
    if len(head) + 2 > width:
        head = f"tick {tick} {status.name}"
    room = width - len(head) - 2
    path = fit_path(labels, room) if labels else "-"
    return f"{head}  {path}" if path and room > 0 else head[:width]


def fit_path(labels: Sequence[str], room: int) -> str:
    """The active path in at most ``room`` columns.

    The first of these that fits: all of it; the root, ``…`` and the deepest nodes (the one
    running now last); ``…`` and the deepest nodes; the deepest node cut short. Whole labels
    are dropped, never halves of them.
    """
    full = SEPARATOR.join(labels)
    if len(full) <= room:
        return full
    for head, first in (([labels[0]], 2), ([], 1)):
        for start in range(first, len(labels)):
            text = SEPARATOR.join([*head, ELLIPSIS, *labels[start:]])
            if len(text) <= room:
                return text
    return labels[-1][:room - 1] + ELLIPSIS if room > 0 else ""


class StatusLine:
    """A live line on ``stream`` of what ``tree`` does, redrawn at most ``redraw_hz`` a second.

    On a terminal the line is redrawn in place; into a pipe or file a line is written when
    the status or the active path changes.
    """

    def __init__(self, tree: Tree, stream: TextIO, *, redraw_hz: float = 10.0,
                 tree_of: Callable[[TickSnapshot], Tree] | None = None,
                 mode_of: Callable[[TickSnapshot], str] | None = None) -> None:
        """Follows ``tree``, or for a mode machine the tree and mode of each tick.

        ``tree_of`` gives the tree that made a snapshot and ``mode_of`` its mode, which the
        line shows first (``[normal] Patrol > ...``).
        """
        self.tree = tree
        self._tree_of = tree_of
        self._mode_of = mode_of
        self.stream = stream
        self.live = stream.isatty()
        self._interval = 1.0 / redraw_hz
        self._drawn_at = 0.0
        self._last_key: tuple[Status, tuple[str, ...]] | None = None
        self._last: TickSnapshot | None = None

    def text(self, snapshot: TickSnapshot, width: int | None = None) -> str:
        """The line of ``snapshot``: ``tick     42  RUNNING  Root tree > Patrol > MoveTo``.

        With ``width``, fitted into that many columns (:func:`fit_status`).
        """
        tree = self._tree_of(snapshot) if self._tree_of is not None else self.tree
        labels = [tree.by_uid[uid].label for uid in snapshot.active if uid in tree.by_uid]
        if self._mode_of is not None and labels:
            labels[0] = f"[{self._mode_of(snapshot)}] {labels[0]}"
        if width is not None:
            return fit_status(snapshot.tick, snapshot.status, labels, width)
        path = SEPARATOR.join(labels) if labels else "-"
        return f"tick {snapshot.tick:>6}  {snapshot.status.name:<7}  {path}"

    def update(self, snapshot: TickSnapshot) -> None:
        """Shows a tick's snapshot (a tick listener: runs on the tick thread)."""
        self._last = snapshot
        if self.live:
            now = time.monotonic()
            if now - self._drawn_at >= self._interval:
                self._drawn_at = now
                self._draw(snapshot)
            return
        key = (snapshot.status, tuple(snapshot.active))
        if key != self._last_key:
            self._last_key = key
            print(self.text(snapshot), file=self.stream, flush=True)

    def _draw(self, snapshot: TickSnapshot) -> None:
        width = terminal_width()
        self.stream.write("\r" + self.text(snapshot, width).ljust(width))
        self.stream.flush()

    def finish(self, *, interrupted: bool = False) -> None:
        """Draws the last tick and ends the line, then says how the run ended."""
        last = self._last
        if self.live:
            if last is not None:
                self._draw(last)
            self.stream.write("\n")
        if last is None:
            print("no tick was run", file=self.stream)
            return
        how = "interrupted" if interrupted else "done"
        print(f"{how} after {last.tick} ticks; last root status {last.status.name}; "
              "running nodes halted", file=self.stream, flush=True)
