"""behavior3 v1 node names, and the cyborg nodes that mean the same.

behavior3editor 1.x and its runtimes (behavior3-ts, behavior3lua) name their stock nodes
differently from behavior3editor 0.3.0, and run trees as a stack machine: a RUNNING node is
resumed on the next tick without re-ticking its ancestors' earlier children. So a v1
``Sequence`` resumes at its running child, which is cyborg's ``MemSequence``. Times are
seconds in v1 and milliseconds in cyborg's (and behavior3's) nodes. :data:`EQUIVALENTS` maps a
v1 name onto cyborg's node and converts its ``args``; :data:`NO_EQUIVALENT` says what the few
v1 stock nodes without a cyborg counterpart do, so an error can tell the user (register a node
class of that name, or run with ``--stub-missing``). docs/behavior3-v1.md has the table.
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from cyborg.bt.problems import shown

Args = dict[str, Any]


def _same(args: Args) -> Args:
    return dict(args)


class ArgError(ValueError):
    """A v1 arg that cannot be converted; :attr:`arg` is its name in the file."""

    def __init__(self, arg: str, message: str) -> None:
        super().__init__(message)
        self.arg = arg


def _seconds(key: str, *, required: bool = False) -> Callable[[Args], Args]:
    """``{key: seconds}`` -> ``{"milliseconds": seconds * 1000}``, other args kept.

    The seconds are checked here, where the file's name and value for them are known: a value
    that is not a finite number of 0 or more (text holding one is fine, as the editor's panel
    writes it), or a ``required`` one that is missing, raises :class:`ArgError` naming ``key``.
    """

    def convert(args: Args) -> Args:
        result = {name: value for name, value in args.items() if name != key}
        if key not in args:
            if required:
                raise ArgError(key, f"missing arg {key!r} (seconds)")
            return result
        seconds = args[key]
        number = None
        if isinstance(seconds, int | float) and not isinstance(seconds, bool):
            number = seconds
        elif isinstance(seconds, str) and len(seconds) <= 100:
            with contextlib.suppress(ValueError):
                number = float(seconds)
        if number is None or not math.isfinite(number) or number < 0:
            raise ArgError(key, f"arg {key!r} must be a finite number of seconds, 0 or more, not "
                                f"{shown(seconds)}")
        result["milliseconds"] = number * 1000
        return result

    return convert


def _renamed(old: str, new: str, absent: Any = None) -> Callable[[Args], Args]:
    def convert(args: Args) -> Args:
        result = {name: value for name, value in args.items() if name != old}
        if old in args:
            result[new] = args[old]
        elif absent is not None:
            result[new] = absent
        return result

    return convert


@dataclass(frozen=True)
class Equivalent:
    """The cyborg node a v1 name stands for, and how its args become our properties."""

    name: str
    note: str = ""
    convert: Callable[[Args], Args] = field(default=_same)
    """The file's args as the node's properties; raises :class:`ArgError` for a bad one."""
    renamed: dict[str, str] = field(default_factory=dict)
    """Property -> the file's arg it comes from, where the names differ."""


EQUIVALENTS: dict[str, Equivalent] = {
    "Sequence": Equivalent("MemSequence", "v1 resumes the running child"),
    "Selector": Equivalent("MemPriority", "v1 resumes the running child"),
    "Parallel": Equivalent("ParallelAll", "v1 waits for every child, then succeeds"),
    "Invert": Equivalent("Inverter"),
    "Inverter": Equivalent("Inverter"),
    "AlwaysSuccess": Equivalent("ForceSuccess"),
    "AlwaysFailure": Equivalent("ForceFailure"),
    "AlwaysFail": Equivalent("ForceFailure", "behavior3lua's name"),
    "JustSuccess": Equivalent("Succeeder"),
    "JustFailure": Equivalent("Failer"),
    "Wait": Equivalent("Wait", "time in seconds -> milliseconds", _seconds("time"),
                       {"milliseconds": "time"}),
    "Timeout": Equivalent("Timeout", "time in seconds -> milliseconds",
                          _seconds("time", required=True), {"milliseconds": "time"}),
    "RepeatUntilSuccess": Equivalent("RetryUntilSuccess", "behavior3lua's name; maxLoop -> count",
                                     _renamed("maxLoop", "count"), {"count": "maxLoop"}),
    "RepeatUntilFailure": Equivalent("RetryUntilFailure", "behavior3lua's name; maxLoop -> count",
                                     _renamed("maxLoop", "count"), {"count": "maxLoop"}),
}
"""v1 name -> cyborg node. Names not here are looked up as they are: most v1 stock nodes
(IfElse, Race, Switch, Case, Watchdog, Once, Repeat, RetryUntilSuccess, Check, Let, ...) are
cyborg stock nodes of the same name (:mod:`cyborg.bt.v1_controls`, :mod:`cyborg.bt.v1_data`,
:mod:`cyborg.bt.v1_math`)."""

NO_EQUIVALENT: dict[str, str] = {
    "Delay": "schedules its child for later and succeeds at once",
    "Listen": "ticks its child when an event fires",
    "WaitForEvent": "runs until an event fires",
    "Loop": "ticks its children a number of times (the editor's sample only)",
}
"""v1 stock nodes with no cyborg counterpart: what each does, for error messages. Delay,
Listen and WaitForEvent need behavior3-ts's event dispatch and deferred callbacks, which a
tree ticked from its root has no place for; Loop has no runtime to take its meaning from."""

REPLACED_IN_CYBORG = frozenset({"Delay"})
"""v1 names that cyborg's own stock nodes use with another meaning: in a v1 file a stock
class of that name is not used for them (a class registered by the user is)."""
