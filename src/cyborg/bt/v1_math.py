"""behavior3 v1's number nodes: Math (behavior3-ts), and Cmp and Random (behavior3lua).

::

    {"name": "Math", "args": {"op": "max"}, "input": ["a", "b", "c"], "output": ["largest"]}
    {"name": "Cmp", "args": {"lt": 50}, "input": ["hp"]}
    {"name": "Random", "args": {"min": 0, "max": 10, "floor": true}, "output": ["roll"]}
"""

from __future__ import annotations

import math
import random
from collections.abc import Callable
from typing import Any

from typing_extensions import override

from cyborg.bt.expressions import Expression
from cyborg.bt.js_values import describe, is_number
from cyborg.bt.node import Action, Condition
from cyborg.bt.status import FAILURE, SUCCESS, NodeError, Status


def _round(value: float) -> float:
    """JavaScript's Math.round: halves go up (``-2.5`` -> ``-2``), not to even."""
    return math.floor(value + 0.5) if math.isfinite(value) else value


def _sign(value: float) -> float:
    return value if value == 0 or value != value else math.copysign(1.0, value)


def _safe(function: Callable[..., float]) -> Callable[..., float]:
    """JavaScript's answer where Python raises: NaN for a domain error, Infinity on overflow."""

    def call(*values: float) -> float:
        try:
            return function(*values)
        except ValueError:
            return math.nan
        except (OverflowError, ZeroDivisionError):
            return math.inf

    return call


def _log(value: float) -> float:
    return -math.inf if value == 0 else math.log(value)


def _rand_int(low: float, high: float) -> float:
    return float(random.randint(math.ceil(low), math.floor(high)))


_ONE: dict[str, Callable[[float], float]] = {
    "abs": abs, "ceil": math.ceil, "floor": math.floor, "round": _round, "sign": _sign,
    "sin": math.sin, "cos": math.cos, "tan": math.tan, "sqrt": math.sqrt, "log": _log}
_TWO: dict[str, Callable[[float, float], float]] = {
    "atan2": math.atan2, "pow": math.pow, "randInt": _rand_int,
    "randFloat": lambda low, high: random.uniform(low, high)}
_MANY: dict[str, Callable[[list[float]], float]] = {
    "min": lambda values: min(values), "max": lambda values: max(values),
    "sum": math.fsum, "average": lambda values: math.fsum(values) / len(values),
    "product": math.prod}
OPS = (*_ONE, *_TWO, *_MANY, "random")
"""Every ``op`` Math knows."""


def _number(value: Any) -> float:
    """JavaScript's Number(): numbers and booleans as they are, numeric text parsed, else NaN."""
    if isinstance(value, bool | int | float):
        return float(value)
    if isinstance(value, str):
        try:
            return float(value.strip() or 0)
        except ValueError:
            return math.nan
    return math.nan


class Math(Action):
    """Applies ``op`` to numbers and writes the result to ``result``; SUCCESS.

    The numbers are ``value1`` and ``value2`` where set, else the inputs in order (unset
    ones skipped); inputs beyond the second are added for min, max, sum, average and product.
    Ops: abs, ceil, floor, round, sign, sin, cos, tan, sqrt, log (one number); atan2, pow,
    randInt, randFloat (two); min, max, sum, average, product (one or more); random (none).
    A wrong count of numbers, or randInt/randFloat with min above max, gives FAILURE (output
    deleted); a NaN result raises, as behavior3-ts reports it as an error.
    """

    inputs = ("values...",)
    outputs = ("result",)

    def __init__(self, op: str, value1: float | None = None,
                 value2: float | None = None) -> None:
        if op not in OPS:
            raise ValueError(f"unknown op {op!r}; Math knows {', '.join(OPS)}")
        self.op = op
        self.value1 = value1
        self.value2 = value2

    def _inputs(self) -> list[float]:
        def position(port: str) -> int:
            return int(port.partition(".")[2] or 1)

        ports = sorted((port for port in self.ports if port.partition(".")[0] == "values"),
                       key=position)
        return [_number(value) for value in map(self.read, ports) if value is not None]

    @override
    def tick(self) -> Status:
        given = self._inputs()
        first = [self.value1] if self.value1 is not None else given[:1]
        second = [self.value2] if self.value2 is not None else given[1:2]
        values = first + second + given[2:]
        result = self._apply(values)
        if result is None:
            self.write("result", None)
            return FAILURE
        if result != result:
            raise NodeError(f"{self.op} of {values} is not a number (NaN)")
        self.write("result", result)
        return SUCCESS

    def _apply(self, values: list[float]) -> float | None:
        op = self.op
        if op == "random":
            return random.random()
        if op in _ONE:
            return _safe(_ONE[op])(values[0]) if len(values) == 1 else None
        if op in _TWO:
            low, high = [*values, math.nan, math.nan][:2]
            if len(values) != 2 or (op == "randFloat" and low > high) or (
                    op == "randInt" and math.ceil(low) > math.floor(high)):
                return None
            return _safe(_TWO[op])(*values)
        return _safe(_MANY[op])(values) if values else None


_COMPARISONS: tuple[tuple[str, Callable[[float, float], bool]], ...] = (
    ("gt", lambda a, b: a > b), ("ge", lambda a, b: a >= b), ("eq", lambda a, b: a == b),
    ("lt", lambda a, b: a < b), ("le", lambda a, b: a <= b))


_NO_COMPARISON = ("Cmp needs one of the args gt, ge, eq, lt, le (the bound to compare the "
                  "value with); none is set")


class Cmp(Condition):
    """Compares a number with the first of ``gt``, ``ge``, ``eq``, ``lt``, ``le`` that is set.

    SUCCESS when the comparison holds, else FAILURE (behavior3lua); none set is a load error.
    The number is the ``value`` input when bound, else the expression ``value``; an unset
    number gives FAILURE, anything else that is not a number is a :class:`NodeError` (ERROR).
    """

    inputs = ("value?",)

    def __init__(self, value: str | None = None, gt: float | None = None,
                 ge: float | None = None, eq: float | None = None, lt: float | None = None,
                 le: float | None = None) -> None:
        self.expression = Expression(value) if value else None
        bounds = {"gt": gt, "ge": ge, "eq": eq, "lt": lt, "le": le}
        self.test: tuple[Callable[[float, float], bool], float] | None = None
        for name, test in _COMPARISONS:
            bound = bounds[name]
            if bound is not None and self.test is None:
                self.test = (test, bound)

    def check(self) -> list[str]:
        """The condition's problems, plus none of ``gt``, ``ge``, ``eq``, ``lt``, ``le`` set.

        behavior3editor's own check of a tree refuses such a Cmp as well.
        """
        problems = super().check()
        if self.test is None:
            problems.append(_NO_COMPARISON)
        return problems

    @override
    def tick(self) -> Status:
        if self.test is None:  # a tree checked at load never has one: check() refuses it
            raise NodeError(_NO_COMPARISON)
        if "value" in self.ports or self.expression is None:
            number = self.read("value")
        else:
            number = self.expression.evaluate(self.blackboard.globals)
        if number is None:
            return FAILURE
        if not is_number(number):
            raise NodeError(f"Cmp compares a number, not {describe(number)}")
        test, bound = self.test
        return SUCCESS if test(number, bound) else FAILURE


class Random(Action):
    """Writes a random number from ``min`` up to ``max`` to ``value``; SUCCESS (behavior3lua).

    The number is rounded down when ``floor``. The ``min``/``max`` inputs, when set, win over
    the args; either not being a number raises.
    """

    inputs = ("min?", "max?")
    outputs = ("value",)

    def __init__(self, min: float | None = None, max: float | None = None,
                 floor: bool = False) -> None:
        self.low, self.high, self.floor = min, max, floor

    @override
    def tick(self) -> Status:
        low, high = self.read("min", self.low), self.read("max", self.high)
        if not (is_number(low) and is_number(high)):
            raise NodeError(f"Random needs numbers for min and max, not {describe(low)} and "
                             f"{describe(high)}")
        value = low + random.random() * (high - low)
        self.write("value", math.floor(value) if self.floor else value)
        return SUCCESS
