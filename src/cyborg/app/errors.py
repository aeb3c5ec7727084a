"""How commands end early: bad input (one line on stderr, exit status 1), or SIGTERM as Ctrl-C."""

from __future__ import annotations


class CommandError(Exception):
    """A problem with the command's input, reported as one line without a traceback."""


def interrupt(_signum: int, _frame: object) -> None:
    """A SIGTERM handler that stops a command as Ctrl-C does (``KeyboardInterrupt``)."""
    raise KeyboardInterrupt
