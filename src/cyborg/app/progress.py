"""A progress bar for long offline runs, drawn on stderr when it is a terminal.

``[#########...........]  45/100 frames  61.2 FPS  0:01 left`` is redrawn in place at most ten
times a second; into a pipe or file one line is written every ten seconds instead.
"""

from __future__ import annotations

import shutil
import time
from typing import TextIO


class ProgressBar:
    def __init__(self, stream: TextIO, total: int | None, unit: str = "frames") -> None:
        self.stream, self.total, self.unit = stream, total, unit
        self.live = stream.isatty()
        self.started = time.monotonic()
        self._drawn = 0.0
        self.done = 0

    def text(self, extra: str = "") -> str:
        elapsed = max(time.monotonic() - self.started, 1e-9)
        rate = self.done / elapsed
        count = f"{self.done}/{self.total}" if self.total else f"{self.done}"
        parts = [f"{count} {self.unit}", f"{rate:.1f} FPS"]
        if self.total and rate > 0:
            left = max(self.total - self.done, 0) / rate
            parts.append(f"{int(left // 60)}:{int(left % 60):02d} left")
        if extra:
            parts.append(extra)
        line = "  ".join(parts)
        if self.total:
            width = max(10, min(40, shutil.get_terminal_size().columns - len(line) - 4))
            filled = int(width * min(self.done / self.total, 1.0))
            line = f"[{'#' * filled}{'.' * (width - filled)}]  {line}"
        return line

    def update(self, done: int, extra: str = "") -> None:
        self.done = done
        now = time.monotonic()
        interval = 0.1 if self.live else 10.0
        if now - self._drawn < interval:
            return
        self._drawn = now
        self._write(extra)

    def _write(self, extra: str) -> None:
        if self.live:
            self.stream.write("\r\x1b[K" + self.text(extra))
        else:
            self.stream.write(self.text(extra) + "\n")
        self.stream.flush()

    def finish(self, extra: str = "") -> None:
        self._write(extra)
        if self.live:
            self.stream.write("\n")
        self.stream.flush()
