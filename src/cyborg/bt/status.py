"""The four results a behaviour-tree node can return, and the error a node raises for ERROR.

The numbers are behavior3's (``SUCCESS=1, FAILURE=2, RUNNING=3, ERROR=4``) so that logs and
messages line up with trees and tools written for behavior3editor. Compare statuses with ``is``:
the members are singletons, and identity checks are the cheapest comparison in the hot path.
"""

from __future__ import annotations

from enum import IntEnum


class Status(IntEnum):
    """Result of ticking a node once."""

    SUCCESS = 1
    """The node reached its goal."""
    FAILURE = 2
    """The node could not reach its goal."""
    RUNNING = 3
    """The node needs more ticks; it will be ticked again or halted."""
    ERROR = 4
    """The node's code raised, or returned something that is not a status."""

    @property
    def label(self) -> str:
        """Lower-case name, as shown in status lines and JSON (``"running"``)."""
        return self.name.lower()

    @classmethod
    def parse(cls, text: str) -> Status:
        """Status from its name in any case (``"success"``, ``"RUNNING"``)."""
        try:
            return cls[text.strip().upper()]
        except KeyError:
            names = ", ".join(member.label for member in cls)
            raise ValueError(f"unknown status {text!r}; expected one of {names}") from None


SUCCESS = Status.SUCCESS
FAILURE = Status.FAILURE
RUNNING = Status.RUNNING
ERROR = Status.ERROR


class NodeError(Exception):
    """A node's own account of why it returns ERROR: a bad input, an unset variable.

    Raise it from ``tick`` (or ``on_start``, ``on_end``, ``on_halt``) with a message that says
    what is wrong in the tree's terms; the node returns ERROR and the message is logged in one
    line, naming the node, with no traceback. Any other exception is a fault in the node's code:
    it is logged with its traceback, which is what finding that fault takes.
    """


class TickInterrupted(BaseException):
    """Raised inside a tick that its loop interrupts (:mod:`cyborg.bt.tick_guard`); says why.

    A :class:`BaseException`, so a node's own ``except Exception`` does not swallow it. Each
    node it passes through is left RUNNING, so the halt that follows reaches it: a node cut off
    after it asked the robot for something (a goal sent) cancels it in ``on_halt``.
    """

    def __init__(self, reason: str = "interrupted") -> None:
        super().__init__(reason)
        self.reason = reason
