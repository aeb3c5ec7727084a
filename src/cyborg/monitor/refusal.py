"""The one error for what a page sent that the monitor will not carry out.

A refusal says why in words the page shows, and where: ``field`` names the field at fault
(None: the message as a whole), ``pos`` the character where a message stopped being JSON.
:func:`cyborg.monitor.commands.receive` answers it as ``{"t": "error", ...}`` or a ``result``
with ``ok: false``; anything else that escapes a command is a fault of the monitor's own,
logged with its traceback. Specific refusals derive from it
(:class:`~cyborg.monitor.limits.MessageError`, :class:`~cyborg.monitor.hub.LimitError`).
"""

from __future__ import annotations

__all__ = ["RefusalError"]


class RefusalError(Exception):
    """A message or command refused; the message says why, ``field`` and ``pos`` where."""

    def __init__(self, message: str, field: str | None = None, pos: int | None = None) -> None:
        super().__init__(message)
        self.field = field
        self.pos = pos
