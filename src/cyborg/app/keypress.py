"""Single keys from a terminal, without Enter: ``p`` pauses a recording, for instance.

:class:`Keys` puts a terminal into cbreak mode while it is used (keys arrive one by one, not
echoed; Ctrl-C still interrupts) and restores the terminal's settings afterwards, also when the
program is interrupted. :meth:`Keys.wait` waits up to a timeout for a key and runs the action
bound to it. Where the input is no terminal (a pipe, a file, a service manager) it only waits,
so a command's loop reads the same either way.
"""

from __future__ import annotations

import os
import select
import termios
import time
import tty
from collections.abc import Callable
from types import TracebackType
from typing import TextIO

Settings = list[int | list[bytes | int]]
"""A terminal's settings as ``termios.tcgetattr`` gives them."""


class Keys:
    """The keys of ``stream`` (a terminal) bound to ``actions``; use it as a context manager."""

    def __init__(self, stream: TextIO, actions: dict[str, Callable[[], object]]) -> None:
        self.stream, self.actions = stream, actions
        self._fd: int | None = None
        self._saved: Settings | None = None

    @property
    def active(self) -> bool:
        """Whether keys are read (the stream is a terminal, and the context is entered)."""
        return self._fd is not None

    def __enter__(self) -> Keys:
        try:
            if self.stream.isatty():
                fd = self.stream.fileno()
                self._saved = termios.tcgetattr(fd)
                tty.setcbreak(fd)
                self._fd = fd
        except (OSError, ValueError, termios.error):
            self._fd = None  # not a usable terminal: wait without keys
        return self

    def __exit__(self, kind: type[BaseException] | None, error: BaseException | None,
                 traceback: TracebackType | None) -> None:
        if self._fd is not None and self._saved is not None:
            termios.tcsetattr(self._fd, termios.TCSADRAIN, self._saved)
        self._fd = None

    def wait(self, timeout: float) -> None:
        """Waits up to ``timeout`` seconds; a bound key pressed meanwhile runs its action."""
        if self._fd is None:
            time.sleep(timeout)
            return
        ready, _, _ = select.select([self._fd], [], [], timeout)
        if ready:
            key = os.read(self._fd, 1).decode("utf-8", errors="ignore").lower()
            action = self.actions.get(key)
            if action is not None:
                action()
