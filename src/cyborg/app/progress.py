"""A progress bar for long offline runs, drawn on stderr when it is a terminal.

``[##########..........]  45/100 frames  61.2 FPS  0:01 left  3 objects`` for a video,
``[####................]  1.2/3.8 MB  850.3 kB/s  0:03 left`` for a download: the unit is what
is counted, and sizes are written in B, kB, MB or GB (powers of 1000, as the download's
``Content-Length`` is). The line is redrawn in place at most ten times a second and always
fits the terminal (less its last column, so it never wraps): when it is narrow, the extra
text goes first, then the time left, then the rate, then the bar; the count stays. Into a pipe
or file one line is written every ten seconds instead.
"""

from __future__ import annotations

import shutil
import time
from contextlib import ExitStack
from typing import Literal, TextIO

from cyborg.app.terminal import LiveTerminal

Unit = Literal["frames", "bytes"]
"""What a bar counts."""

BAR_WIDTH = (10, 40)
"""Narrowest and widest bar, in columns; narrower than this, no bar is drawn."""


def terminal_width() -> int:
    """The columns a line may use: the terminal's (``$COLUMNS`` first, else 80) less one.

    A character in the last column would make some terminals wrap.
    """
    return shutil.get_terminal_size((80, 24)).columns - 1


def size(count: float, unit: str | None = None) -> str:
    """``512 B``, ``2.0 kB``, ``3.8 MB``; with ``unit`` (``"MB"``), in that unit."""
    units = {"B": 1, "kB": 1e3, "MB": 1e6, "GB": 1e9}
    if unit is None:
        unit = next((name for name, scale in reversed(units.items()) if count >= scale), "B")
    value = count / units[unit]
    return f"{value:.0f} {unit}" if unit == "B" else f"{value:.1f} {unit}"


def duration(seconds: float) -> str:
    """``0:07``, ``12:30``, ``1:02:03``."""
    whole = int(seconds)
    hours, minutes, secs = whole // 3600, whole // 60 % 60, whole % 60
    return f"{hours}:{minutes:02d}:{secs:02d}" if hours else f"{minutes}:{secs:02d}"


class ProgressBar:
    """A progress line on ``stream``, counting ``unit`` up to ``total`` (None: unknown)."""

    def __init__(self, stream: TextIO, total: int | None, unit: Unit = "frames") -> None:
        self.stream, self.total, self.unit = stream, total, unit
        self.live = stream.isatty()
        self.started = time.monotonic()
        self._drawn = 0.0
        self._updated = False
        self.done = 0

    def _count(self) -> str:
        if self.unit == "bytes":
            if not self.total:
                return size(self.done)
            total, unit = size(self.total).split()
            return f"{size(self.done, unit).split()[0]}/{total} {unit}"  # 1.2/3.8 MB
        count = f"{self.done}/{self.total}" if self.total else f"{self.done}"
        return f"{count} frames"

    def _rate(self, rate: float) -> str:
        return f"{size(rate)}/s" if self.unit == "bytes" else f"{rate:.1f} FPS"

    def text(self, extra: str = "", width: int | None = None) -> str:
        """The line as it is drawn now, at most ``width`` columns (default: the terminal's)."""
        width = terminal_width() if width is None else width
        elapsed = max(time.monotonic() - self.started, 1e-9)
        rate = self.done / elapsed
        parts = [self._count(), self._rate(rate)]
        if self.total and rate > 0:
            parts.append(f"{duration(max(self.total - self.done, 0) / rate)} left")
        if extra:
            parts.append(extra)
        while len(parts) > 1 and len("  ".join(parts)) > width:
            parts.pop()  # the least telling part goes first
        line = "  ".join(parts)[:width]
        bar = min(BAR_WIDTH[1], width - len(line) - 4)  # "[" bar "]  " line
        if self.total and bar >= BAR_WIDTH[0]:
            filled = int(bar * min(self.done / self.total, 1.0))
            line = f"[{'#' * filled}{'.' * (bar - filled)}]  {line}"
        return line

    def update(self, done: int, extra: str = "") -> None:
        """Sets the count to ``done``; redraws when due, with ``extra`` text at the end."""
        self.done, self._updated = done, True
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
        """Draws the last state and ends the line; nothing if there was never an update."""
        if not self._updated:
            return
        self._write(extra)
        if self.live:
            self.stream.write("\n")
        self.stream.flush()


class LiveLine:
    """A line of what a long-running command does now, on ``stream``; :meth:`text` says what.

    Redrawn in place ten times a second on a terminal, cut to its width, with log records and
    prints written on rows above it from its first drawing to :meth:`clear`
    (:mod:`cyborg.app.terminal`); into a pipe or file, one line every ten seconds.
    ``cyborg record`` and ``cyborg play`` show theirs so.
    """

    def __init__(self, stream: TextIO) -> None:
        self.stream = stream
        self.live = stream.isatty()
        self._drawn = 0.0
        self.terminal = LiveTerminal(stream)
        self._attached: ExitStack | None = None

    def text(self) -> str:
        """The line as it is now (a subclass says it)."""
        raise NotImplementedError

    def fitted(self, line: str) -> str:
        """``line`` cut to the terminal's width when drawn in place."""
        return line[:terminal_width()] if self.live else line

    def update(self) -> None:
        """Redraws the line when due."""
        now = time.monotonic()
        if now - self._drawn < (0.1 if self.live else 10.0):
            return
        self._drawn = now
        if not self.live:
            self.stream.write(self.text() + "\n")
            self.stream.flush()
            return
        if self._attached is None:
            self._attached = ExitStack()
            self._attached.enter_context(self.terminal.attached())
        self.terminal.draw(self.text())

    def clear(self) -> None:
        """Wipes the line drawn in place, so that a summary can take its place."""
        if self.live:
            self.terminal.wipe()
        if self._attached is not None:
            self._attached.close()
            self._attached = None
