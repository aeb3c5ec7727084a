"""behavior3 v1 node names, and the cyborg nodes that mean the same.

behavior3editor 1.x and its runtimes (behavior3-ts, behavior3lua) name their stock nodes
differently from behavior3editor 0.3.0, and run trees as a stack machine: a RUNNING node is
resumed on the next tick without re-ticking its ancestors' earlier children. So a v1
``Sequence`` resumes at its running child, which is cyborg's ``MemSequence``. Times are
seconds in v1 and milliseconds in cyborg's (and behavior3's) nodes. :data:`EQUIVALENTS` maps a
v1 name onto cyborg's node and converts its ``args``; :data:`NO_EQUIVALENT` says what the v1
stock nodes without a cyborg counterpart do, so an error can tell the user (register a node
class of that name, or run with ``--stub-missing``). docs/behavior3-v1.md has the table.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

Args = dict[str, Any]


def _same(args: Args) -> Args:
    return dict(args)


def _seconds(key: str) -> Callable[[Args], Args]:
    """``{key: seconds}`` -> ``{"milliseconds": seconds * 1000}``, other args kept."""

    def convert(args: Args) -> Args:
        result = {name: value for name, value in args.items() if name != key}
        seconds = args.get(key)
        if isinstance(seconds, int | float) and not isinstance(seconds, bool):
            result["milliseconds"] = seconds * 1000
        elif key in args:
            result["milliseconds"] = seconds  # the node's own check names the bad value
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


EQUIVALENTS: dict[str, Equivalent] = {
    "Sequence": Equivalent("MemSequence", "v1 resumes the running child"),
    "Selector": Equivalent("MemPriority", "v1 resumes the running child"),
    "Invert": Equivalent("Inverter"),
    "Inverter": Equivalent("Inverter"),
    "AlwaysSuccess": Equivalent("ForceSuccess"),
    "AlwaysFailure": Equivalent("ForceFailure"),
    "AlwaysFail": Equivalent("ForceFailure", "behavior3lua's name"),
    "JustSuccess": Equivalent("Succeeder"),
    "JustFailure": Equivalent("Failer"),
    "Wait": Equivalent("Wait", "time in seconds -> milliseconds", _seconds("time")),
    "Timeout": Equivalent("Timeout", "time in seconds -> milliseconds", _seconds("time")),
    "RetryUntilSuccess": Equivalent("Retry", "count -> maxAttempts (none: forever)",
                                    _renamed("count", "maxAttempts", absent=-1)),
    "RepeatUntilSuccess": Equivalent("RepeatUntilSuccess", "behavior3lua's maxLoop"),
}
"""v1 name -> cyborg node. Names not here are looked up as they are."""

NO_EQUIVALENT: dict[str, str] = {
    "Parallel": "ticks every child until all have finished, then succeeds",
    "Race": "ticks every child until one succeeds",
    "IfElse": "ticks child 2 or 3 by the result of child 1",
    "Switch": "runs the first Case whose condition succeeds",
    "Case": "a condition and a branch, inside Switch",
    "Watchdog": "re-checks a guard every tick while a branch runs",
    "Delay": "schedules its child for later and succeeds at once",
    "Listen": "ticks its child when an event fires",
    "Once": "succeeds the first time its child completes, then fails",
    "Repeat": "ticks its child count times, stopping at a failure",
    "RetryUntilFailure": "succeeds when its child fails, fails after count tries",
    "RepeatUntilFailure": "repeats its child until it fails, up to maxLoop times (behavior3lua)",
    "Assert": "raises when its child fails",
    "ForEach": "ticks its child for each element of an array",
    "Filter": "keeps the array elements its child succeeds on",
    "Loop": "ticks its children a number of times",
    "Check": "evaluates an expression over blackboard variables",
    "Cmp": "compares a blackboard value with numbers (behavior3lua)",
    "Calculate": "evaluates an expression into a variable",
    "WaitForEvent": "runs until an event fires",
    "WaitForCount": "runs for a number of ticks (behavior3lua)",
    "Includes": "tests whether an array holds an element",
    "Push": "appends to an array",
    "Concat": "joins two arrays",
    "Index": "reads an array element",
    "GetField": "reads an object field",
    "SetField": "writes an object field",
    "RandomIndex": "picks a random array element",
    "Random": "writes a random number (behavior3lua)",
    "Math": "applies a math function",
    "Clear": "deletes a variable",
}
"""v1 stock nodes with no cyborg counterpart: what each does, for error messages."""

REPLACED_IN_CYBORG = frozenset({"Parallel", "Delay", "RepeatUntilFailure"})
"""v1 names that cyborg's own stock nodes use with another meaning: in a v1 file a stock
class of that name is not used for them (a class registered by the user is)."""
