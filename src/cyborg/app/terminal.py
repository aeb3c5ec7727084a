"""One terminal shared by a live line and everything else that writes to it.

A live line (:class:`~cyborg.app.status_line.StatusLine`) is redrawn in place at the bottom
of the terminal. Whatever else is written meanwhile — a log record, a node's ``print()`` —
must not be appended to it (``…MoveTo room1   WARNING cyborg.robot: …`` on one row). While a
:class:`LiveTerminal` is :meth:`~LiveTerminal.attached`, as tqdm and rich do, each such write
clears the line, is written on a row of its own, and the line is drawn again below it:

* log records of the root logger's handlers that write to a terminal go through
  :class:`AboveTheLine`, which hands each record to the handler inside
  :meth:`LiveTerminal.above`;
* ``sys.stdout`` is replaced by :class:`LinesAbove`, which writes each complete line of
  ``print()`` the same way (a partial line waits for its end, or for :meth:`detach`).

:class:`OneLineErrors` writes a record's exception as one line (its type, text and where it
was raised) instead of a traceback: ``cyborg bt run`` reports a node's error so.
:class:`NamesRobot` puts the robot first in a record of a fleet's tree runner that does not
name it.
"""

from __future__ import annotations

import logging
import sys
import threading
import traceback
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from typing import TextIO

CLEAR = "\r\x1b[K"
"""Back to the row's start and wipe it."""


class LiveTerminal:
    """The live line on ``stream`` and the writes that go above it; thread-safe."""

    def __init__(self, stream: TextIO) -> None:
        self.stream = stream
        self._line = ""
        self._lock = threading.RLock()

    def draw(self, text: str) -> None:
        """Draws ``text`` as the live line, in place of the one drawn before."""
        with self._lock:
            self._line = text
            self.stream.write(CLEAR + text)
            self.stream.flush()

    def above(self, write: Callable[[], object]) -> None:
        """Runs ``write`` (which writes whole lines) on a cleared row, then draws the line again."""
        with self._lock:
            if self._line:
                self.stream.write(CLEAR)
                self.stream.flush()
            write()
            if self._line:
                self.stream.write(self._line)
                self.stream.flush()

    def wipe(self) -> None:
        """Wipes the live line, so that what follows takes its row."""
        with self._lock:
            if self._line:
                self.stream.write(CLEAR)
                self.stream.flush()
            self._line = ""

    def end(self) -> None:
        """Ends the live line: what follows starts on a row of its own."""
        with self._lock:
            if self._line:
                self.stream.write("\n")
                self.stream.flush()
            self._line = ""

    @contextmanager
    def attached(self) -> Iterator[None]:
        """While inside, log records and ``print()`` go above the live line (see the module)."""
        root = logging.getLogger()
        handlers = list(root.handlers)
        root.handlers = [AboveTheLine(self, handler) if _writes_to_terminal(handler)
                         else handler for handler in handlers]
        stdout = sys.stdout
        lines = LinesAbove(self, stdout)
        sys.stdout = lines
        try:
            yield
        finally:
            if sys.stdout is lines:
                sys.stdout = stdout
            lines.detach()
            root.handlers = handlers


def _writes_to_terminal(handler: logging.Handler) -> bool:
    stream = getattr(handler, "stream", None)
    return isinstance(handler, logging.StreamHandler) and stream is not None \
        and hasattr(stream, "isatty") and stream.isatty()


class AboveTheLine(logging.Handler):
    """Hands each record to ``handler``, written above ``terminal``'s live line."""

    def __init__(self, terminal: LiveTerminal, handler: logging.Handler) -> None:
        super().__init__(handler.level)
        self.terminal, self.handler = terminal, handler

    def emit(self, record: logging.LogRecord) -> None:
        """Writes the record through the handler, on a row of its own."""
        self.terminal.above(lambda: self.handler.handle(record))


class LinesAbove:
    """A text stream (for ``sys.stdout``) whose complete lines go above a live line."""

    def __init__(self, terminal: LiveTerminal, stream: TextIO) -> None:
        self.terminal, self.stream = terminal, stream
        self._partial = ""
        self._lock = threading.Lock()

    def write(self, text: str) -> int:
        """Writes the complete lines of what was written so far; keeps a partial one."""
        with self._lock:
            text = self._partial + text
            complete, _, self._partial = text.rpartition("\n")
        if complete:
            self.terminal.above(lambda: self._out(complete + "\n"))
        return len(text)

    def _out(self, text: str) -> None:
        self.stream.write(text)
        self.stream.flush()

    def flush(self) -> None:
        """Nothing to do: complete lines are written at once."""

    def isatty(self) -> bool:
        """Whether the stream underneath is a terminal."""
        return self.stream.isatty()

    def detach(self) -> None:
        """Writes a partial line left over (ended, so that the live line's end follows it)."""
        with self._lock:
            partial, self._partial = self._partial, ""
        if partial:
            self.terminal.above(lambda: self._out(partial + "\n"))

    def __getattr__(self, name: str) -> object:
        return getattr(self.stream, name)


class OneLineErrors(logging.Formatter):
    """A formatter that writes a record's exception on the record's line, not as a traceback.

    ``…: ValueError: bad (at nodes.py:12 in tick)``: the type, the text, and the innermost
    frame's file, line and function.
    """

    def format(self, record: logging.LogRecord) -> str:
        """The record on one line, its exception included."""
        if not record.exc_info or record.exc_info[1] is None:
            return super().format(record)
        exc = record.exc_info[1]
        frames = traceback.extract_tb(exc.__traceback__)
        where = f" (at {frames[-1].filename}:{frames[-1].lineno} in {frames[-1].name})" \
            if frames else ""
        one_line = logging.makeLogRecord(record.__dict__)
        one_line.msg = f"{record.getMessage()}: {type(exc).__name__}: {exc}{where}"
        one_line.args, one_line.exc_info, one_line.exc_text = (), None, None
        return super().format(one_line)


@contextmanager
def errors_on_one_line() -> Iterator[None]:
    """While inside, the root logger's handlers write exceptions on one line (OneLineErrors).

    Above a live line too: the handler a wrapper hands records to is the one changed.
    """
    root = logging.getLogger()
    formatters = [(handler, handler.formatter) for handler in
                  (_written_by(handler) for handler in root.handlers)]
    for handler, formatter in formatters:
        handler.setFormatter(OneLineErrors(formatter._fmt if formatter is not None else None))
    try:
        yield
    finally:
        for handler, formatter in formatters:
            handler.setFormatter(formatter)


FLEET_WIDE = "fleet_wide"
"""A record's attribute (``extra={FLEET_WIDE: True}``) that says it is about every robot."""


def _written_by(handler: logging.Handler) -> logging.Handler:
    """The handler that formats what ``handler`` is given (the one above a live line wraps)."""
    return handler.handler if isinstance(handler, AboveTheLine) else handler


class NamesRobot(logging.Filter):
    """Puts the robot first (``/robot2: …``) in a record logged for one robot of a fleet.

    The robot is the namespace in the name of the thread that logged the record (a tree
    runner's thread, a bus node's callback thread); a record that names it already, that
    comes from no robot's thread, or that is :data:`FLEET_WIDE`, is left as it is.
    """

    def __init__(self, namespaces: Sequence[str]) -> None:
        super().__init__()
        self.namespaces = [namespace.rstrip("/") for namespace in namespaces]

    def filter(self, record: logging.LogRecord) -> bool:
        """Adds the robot to the message where it is missing; never drops a record."""
        if getattr(record, FLEET_WIDE, False):
            return True
        robot = next((namespace for namespace in self.namespaces
                      if f"{namespace}/" in f"{record.threadName}/"), None)
        if robot is not None:
            message = record.getMessage()
            if robot not in message:
                record.msg, record.args = f"{robot}: {message}", ()
        return True
