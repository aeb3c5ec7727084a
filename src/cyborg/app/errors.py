"""The error every command raises for bad input: one line on stderr, exit status 1."""

from __future__ import annotations


class CommandError(Exception):
    """A problem with the command's input, reported as one line without a traceback."""
