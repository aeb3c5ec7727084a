"""A one-line live view of a running tree: tick count, root status and active path.

On a terminal the line is redrawn in place (at most 10 times a second) and always fits it
(:func:`fit_status`): the tick and the root status stay, and a long active path is shortened
from the middle, keeping the root and the nodes running now. Into a pipe or file a new line,
in full, is written only when the root status or the active path changes, so logs stay short.

While the line is live, log records and ``print()`` are written on rows of their own above it
(:mod:`cyborg.app.terminal`). Given the ``speed`` simulated time was asked to run at, the live
line shows the pace it reaches (``7.1x/30x``, :class:`~cyborg.app.rate_window.PaceWindow`), and
a warning says once when it stays below half of that
(:class:`~cyborg.app.rate_window.FallingBehind`).
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable, Sequence
from contextlib import ExitStack
from typing import TextIO

from cyborg.app.progress import terminal_width
from cyborg.app.rate_window import FallingBehind, PaceWindow
from cyborg.app.terminal import FLEET_WIDE, LiveTerminal
from cyborg.bt import Status, Tree
from cyborg.bt.snapshot import TickSnapshot

SEPARATOR, ELLIPSIS = " > ", "…"
"""What stands between two labels of the path, and for the labels left out."""
log = logging.getLogger("cyborg.app")
"""Where the warning of a pace fallen behind goes."""


def fit_status(tick: int, status: Status, labels: Sequence[str], width: int,
               pace: str = "") -> str:
    """The line of one tick, ``tick 42  RUNNING  Root tree > … > MoveTo``, in ``width`` columns.

    The tick number and the status are always there (with single spaces when the line is very
    narrow), then ``pace`` if given and there is room; the active path (root first) takes what
    room is left.
    """
    head = f"tick {tick:>6}  {status.name:<7}"
    if pace and len(head) + len(pace) + 4 <= width:
        head = f"{head}  {pace}"
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
                 mode_of: Callable[[TickSnapshot], str] | None = None,
                 speed: float | None = None,
                 wall: Callable[[], float] = time.monotonic) -> None:
        """Follows ``tree``, or for a mode machine the tree and mode of each tick.

        ``tree_of`` gives the tree that made a snapshot and ``mode_of`` its mode, which the
        line shows first (``[normal] Patrol > ...``). ``speed``: the pace simulated time was
        asked to run at (0: as fast as possible), for a tree on simulated time; ``wall`` is
        the wall clock the pace is measured on.
        """
        self.tree = tree
        self._tree_of = tree_of
        self._mode_of = mode_of
        self.stream = stream
        self.live = stream.isatty()
        self.terminal = LiveTerminal(stream)
        self._attached = ExitStack()
        self._interval = 1.0 / redraw_hz
        self._wall = wall
        self._drawn_at = -self._interval
        self._last_key: tuple[Status, tuple[str, ...]] | None = None
        self._last: TickSnapshot | None = None
        self.speed = speed
        self.pace = PaceWindow(wall) if speed is not None else None
        self.behind = FallingBehind(speed, wall) if speed is not None else None

    def attach(self) -> None:
        """From now until :meth:`finish`, log records and prints go above the live line."""
        if self.live:
            self._attached.enter_context(self.terminal.attached())

    def pace_text(self) -> str:
        """``7.1x/30x``: the pace reached and the one asked; empty while unknown."""
        pace = self.pace.pace() if self.pace is not None else None
        if pace is None or self.speed is None:
            return ""
        asked = "max" if self.speed == 0 else f"{self.speed:g}x"
        return f"{pace:.1f}x/{asked}"

    def text(self, snapshot: TickSnapshot, width: int | None = None) -> str:
        """The line of ``snapshot``: ``tick     42  RUNNING  Root tree > Patrol > MoveTo``.

        With ``width``, fitted into that many columns (:func:`fit_status`).
        """
        tree = self._tree_of(snapshot) if self._tree_of is not None else self.tree
        labels = [tree.by_uid[uid].label for uid in snapshot.active if uid in tree.by_uid]
        if self._mode_of is not None and labels:
            labels[0] = f"[{self._mode_of(snapshot)}] {labels[0]}"
        if width is not None:
            return fit_status(snapshot.tick, snapshot.status, labels, width, self.pace_text())
        path = SEPARATOR.join(labels) if labels else "-"
        return f"tick {snapshot.tick:>6}  {snapshot.status.name:<7}  {path}"

    def update(self, snapshot: TickSnapshot) -> None:
        """Shows a tick's snapshot (a tick listener: runs on the tick thread)."""
        self._last = snapshot
        if self.pace is not None and self.behind is not None:
            self.pace.add(snapshot.time)
            warning = self.behind.check(self.pace.pace())
            if warning is not None:  # of the whole simulation, not of one robot
                log.warning(warning, extra={FLEET_WIDE: True})
        if self.live:
            now = self._wall()
            if now - self._drawn_at >= self._interval:
                self._drawn_at = now
                self._draw(snapshot)
            return
        key = (snapshot.status, tuple(snapshot.active))
        if key != self._last_key:
            self._last_key = key
            print(self.text(snapshot), file=self.stream, flush=True)

    def _draw(self, snapshot: TickSnapshot) -> None:
        self.terminal.draw(self.text(snapshot, terminal_width()))

    def finish(self, *, interrupted: bool = False) -> None:
        """Draws the last tick and ends the line, then says how the run ended."""
        last = self._last
        if self.live:
            if last is not None:
                self._draw(last)
            self.terminal.end()
            self._attached.close()
        if last is None:
            print("no tick was run", file=self.stream)
            return
        how = "interrupted" if interrupted else "done"
        print(f"{how} after {last.tick} ticks; last root status {last.status.name}; "
              "running nodes halted", file=self.stream, flush=True)
