"""JavaScript's value rules, as behavior3 v1 trees expect them.

They cover truthiness, ``===``, number text, 32-bit bitwise arithmetic, ``/`` and ``%`` by zero,
and reading ``a[k]``. behavior3-ts runs in JavaScript, so a tree drawn for it counts on these
rules; cyborg's expression evaluator (:mod:`cyborg.bt.expressions`) and the v1 data nodes
(:mod:`cyborg.bt.v1_data`) apply them to Python values: ``None`` is both ``null`` and
``undefined``, lists are arrays, dicts (any mapping) are objects.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from typing import Any


def truthy(value: Any) -> bool:
    """JavaScript's truthiness of ``value``.

    false, 0, NaN, "" and null/undefined are false; every other value, including an empty list
    or dict, is true.
    """
    if value is None or value is False:
        return False
    if isinstance(value, int | float):
        return value == value and value != 0
    if isinstance(value, str):
        return value != ""
    return True


def strict_equal(a: Any, b: Any) -> bool:
    """JavaScript's ``a === b``.

    Numbers compare by value (NaN equals nothing), strings and booleans by value, lists and
    dicts only when they are the same object.
    """
    if is_number(a) and is_number(b):
        return bool(a == b)
    if type(a) is bool or type(b) is bool:
        return a is b
    if a is None or b is None or isinstance(a, str) or isinstance(b, str):
        return type(a) is type(b) and bool(a == b)
    return a is b


def js_text(value: Any) -> str:
    """How JavaScript writes a primitive value (``3``, ``2.5``, ``true``, ``NaN``)."""
    if value is None:
        return "undefined"
    if type(value) is bool:
        return "true" if value else "false"
    if isinstance(value, float):
        if value != value:
            return "NaN"
        if math.isinf(value):
            return "Infinity" if value > 0 else "-Infinity"
        if value.is_integer() and abs(value) < 1e21:
            return str(int(value))
    return str(value)


def describe(value: Any) -> str:
    """A value as an error message shows it: ``undefined``, ``3``, ``'text'``, ``a list``."""
    if isinstance(value, list | tuple):
        return "a list"
    if isinstance(value, Mapping):
        return "an object"
    if value is None or isinstance(value, int | float):
        return js_text(value)
    if isinstance(value, str):
        return repr(value)
    name = type(value).__name__
    return f"{'an' if name[:1].lower() in 'aeiou' else 'a'} {name}"


def is_number(value: Any) -> bool:
    """An int or float, but not a bool (Python's bools are ints; JavaScript's are not)."""
    return isinstance(value, int | float) and type(value) is not bool


SAFE_INTEGER = 2**53
"""Beyond this, JavaScript's numbers (doubles) no longer hold every integer."""


def js_number(value: float) -> float:
    """``value`` as JavaScript holds a number: a double past :data:`SAFE_INTEGER`.

    An int beyond it becomes the nearest double (``±Infinity`` past the largest), so no
    arithmetic grows without bound; ints within it stay ints (``3`` shows as ``3``, as
    JavaScript shows it).
    """
    if isinstance(value, int) and not -SAFE_INTEGER <= value <= SAFE_INTEGER:
        try:
            return float(value)
        except OverflowError:
            return math.inf if value > 0 else -math.inf
    return value


def int32(value: float) -> int:
    """JavaScript's ToInt32, which bitwise operators apply: truncate, wrap to 32-bit signed."""
    if isinstance(value, float) and not math.isfinite(value):
        return 0
    number = int(value) & 0xFFFFFFFF
    return number - 0x100000000 if number & 0x80000000 else number


def _divide(a: float, b: float) -> float:
    if b == 0:
        if a == 0 or a != a:
            return math.nan
        return math.copysign(math.inf, a) * math.copysign(1.0, b)
    return a / b


def _remainder(a: float, b: float) -> float:
    if b == 0 or (isinstance(a, float) and math.isinf(a)):
        return math.nan
    if isinstance(a, int) and isinstance(b, int):
        result = abs(a) % abs(b)
        return -result if a < 0 else result
    return math.fmod(a, b)


ARITHMETIC: dict[str, Callable[[Any, Any], Any]] = {
    "-": lambda a, b: a - b, "*": lambda a, b: a * b, "/": _divide, "%": _remainder,
    "<<": lambda a, b: int32(int32(a) << (int32(b) & 31)),
    ">>": lambda a, b: int32(a) >> (int32(b) & 31),
    ">>>": lambda a, b: (int32(a) & 0xFFFFFFFF) >> (int32(b) & 31),
    "&": lambda a, b: int32(a) & int32(b), "|": lambda a, b: int32(a) | int32(b),
    "^": lambda a, b: int32(a) ^ int32(b),
}
ORDER: dict[str, Callable[[Any, Any], bool]] = {
    "<": lambda a, b: a < b, "<=": lambda a, b: a <= b,
    ">": lambda a, b: a > b, ">=": lambda a, b: a >= b,
}


def read_member(target: Any, key: Any) -> Any:
    """``target[key]`` as JavaScript reads it; ``None`` (undefined) when absent.

    It reads a dict's key (a number also finds its text, as object keys are text in JavaScript),
    a list's or string's element or ``length``. Raises TypeError when ``target`` is not a dict,
    list or string.
    """
    if isinstance(target, Mapping):
        if isinstance(key, str):
            return target.get(key)
        if is_number(key) and key in target:
            return target[key]
        return target.get(js_text(key)) if isinstance(key, int | float) else None
    if isinstance(target, list | tuple | str):
        if key == "length":
            return len(target)
        if isinstance(key, str) and key.isdigit():
            key = int(key)
        if is_number(key) and math.isfinite(key) and key == int(key) \
                and 0 <= key < len(target):
            return target[int(key)]
        return None
    raise TypeError(f"cannot read a field of a {type(target).__name__}")
