"""Stock nodes that look at the blackboard through ports: Log, IsNull and NotNull.

They come from behavior3 v1 (behavior3-ts), where trees pass data between nodes in
blackboard variables named by each node's ``input``/``output`` (see :mod:`cyborg.bt.ports`)::

    {"name": "IsNull", "input": ["target"]}            # SUCCESS while "target" is unset
    {"name": "Log", "args": {"message": "no target"}, "input": ["target"]}
"""

from __future__ import annotations

import logging

from typing_extensions import override

from cyborg.bt.node import Action, Condition
from cyborg.bt.status import FAILURE, SUCCESS, Status

log = logging.getLogger("cyborg.bt.log")

_LEVELS = {"log": logging.INFO, "info": logging.INFO, "debug": logging.DEBUG,
           "warn": logging.WARNING, "warning": logging.WARNING, "error": logging.ERROR}


class Log(Action):
    """Logs ``message`` on the ``cyborg.bt.log`` logger, then returns SUCCESS.

    ``level`` is log (as info), debug, info, warn or error. When the ``value`` port is bound,
    the value it reads follows the message.
    """

    inputs = ("value?",)

    def __init__(self, message: str = "", level: str = "log") -> None:
        if level.lower() not in _LEVELS:
            raise ValueError(f"level must be one of {', '.join(_LEVELS)}, not {level!r}")
        self.message = message
        self.level = _LEVELS[level.lower()]

    @override
    def tick(self) -> Status:
        if "value" in self.ports:
            log.log(self.level, "%s %r", self.message, self.read("value"))
        else:
            log.log(self.level, "%s", self.message)
        return SUCCESS


class IsNull(Condition):
    """SUCCESS when the variable bound to ``value`` is unset (or None), else FAILURE."""

    inputs = ("value",)

    @override
    def tick(self) -> Status:
        return SUCCESS if self.read("value") is None else FAILURE


class NotNull(Condition):
    """SUCCESS when the variable bound to ``value`` holds something, else FAILURE."""

    inputs = ("value",)

    @override
    def tick(self) -> Status:
        return FAILURE if self.read("value") is None else SUCCESS
