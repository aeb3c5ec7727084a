"""A one-line live view of a running tree: tick count, root status and active path.

On a terminal the line is redrawn in place (at most 10 times a second). Into a pipe or file a
new line is written only when the root status or the active path changes, so logs stay short.
"""

from __future__ import annotations

import shutil
import time
from typing import TextIO

from cyborg.bt import Status, Tree
from cyborg.bt.snapshot import TickSnapshot


class StatusLine:
    def __init__(self, tree: Tree, stream: TextIO, *, redraw_hz: float = 10.0) -> None:
        self.tree = tree
        self.stream = stream
        self.live = stream.isatty()
        self._interval = 1.0 / redraw_hz
        self._drawn_at = 0.0
        self._last_key: tuple[Status, tuple[str, ...]] | None = None
        self._last: TickSnapshot | None = None

    def text(self, snapshot: TickSnapshot) -> str:
        """``tick 42  RUNNING  Root tree > Priority > Patrol tree > MoveTo room1``."""
        labels = [self.tree.by_uid[uid].label for uid in snapshot.active]
        path = " > ".join(labels) if labels else "-"
        return f"tick {snapshot.tick:>6}  {snapshot.status.name:<7}  {path}"

    def update(self, snapshot: TickSnapshot) -> None:
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
        width = shutil.get_terminal_size().columns - 1
        text = self.text(snapshot)
        if len(text) > width:
            text = "…" + text[-(width - 1):]
        self.stream.write("\r" + text.ljust(width))
        self.stream.flush()

    def finish(self, *, interrupted: bool = False) -> None:
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
