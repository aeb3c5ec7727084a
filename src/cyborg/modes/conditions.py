"""Transition conditions: the engine's safe expressions, read against the global blackboard.

A condition such as ``battery.percent < 20 && !docked`` is parsed once, when the mode file is
read, by :class:`cyborg.bt.expressions.Expression` (the language of behavior3 v1's ``expr``
args: no ``eval``, JavaScript's operators and value rules; docs/modes.md lists them). A parse
error is a load error with its column.

Names are keys of the blackboard's **global** scope; ``a.b`` reads a key of a dict, an element
of a list, or a public attribute of any other object (a message such as ``BatteryStatus``), so
``battery.percent`` works whether a node stored a dict or the message itself. Methods and
names starting with ``_`` are never reachable: they read as ``undefined``.

A condition is true when its value is truthy in JavaScript's sense. One that cannot be
evaluated (``battery.percent < 20`` before anything wrote ``battery``: ``undefined < 20``) is
false; the error is kept in :attr:`Condition.last_error` and logged once until it changes.
"""

from __future__ import annotations

import logging
from collections.abc import Iterator, Mapping
from typing import Any

from cyborg.bt.expressions import Expression, ExpressionError
from cyborg.bt.js_values import truthy

log = logging.getLogger("cyborg.modes")


class Condition:
    """A parsed condition; :class:`ExpressionError` (with the column) if it does not parse."""

    __slots__ = ("expression", "last_error", "source")

    def __init__(self, source: str) -> None:
        self.source = source
        self.expression = Expression(source)
        self.last_error: str | None = None
        """Why the last evaluation failed, or None if it did not."""

    def holds(self, variables: Mapping[str, Any]) -> bool:
        """Whether the condition is true for ``variables`` (the global blackboard)."""
        try:
            value = self.expression.evaluate(ObjectView(variables))
        except Exception as exc:  # an ExpressionError, or an object's property that raised
            message = str(exc) if isinstance(exc, ExpressionError) else (
                f"in {self.source!r}: reading a value raised {type(exc).__name__}: {exc}")
            if message != self.last_error:
                log.warning("condition %r is taken as false: %s", self.source, message)
            self.last_error = message
            return False
        self.last_error = None
        return truthy(value)

    def __repr__(self) -> str:
        return f"Condition({self.source!r})"


class ObjectView(Mapping[str, Any]):
    """A read-only view of a mapping or object whose values are views again where needed.

    Mappings are read by key, other objects by their public, non-callable attributes
    (``__slots__``, dataclass fields, instance attributes); plain values pass through.
    """

    __slots__ = ("_target",)

    def __init__(self, target: Any) -> None:
        self._target = target

    def __getitem__(self, key: str) -> Any:
        target = self._target
        if isinstance(target, Mapping):
            value = target[key]
        else:
            if not isinstance(key, str) or key.startswith("_"):
                raise KeyError(key)
            try:
                value = getattr(target, key)
            except AttributeError:
                raise KeyError(key) from None
            if callable(value):
                raise KeyError(key)
        return view(value)

    def __iter__(self) -> Iterator[str]:
        target = self._target
        if isinstance(target, Mapping):
            return iter(target)
        return iter(name for name in _attributes(target) if not name.startswith("_"))

    def __len__(self) -> int:
        return sum(1 for _ in self)


def view(value: Any) -> Any:
    """``value`` as an expression reads it: objects and mappings wrapped, lists of them too."""
    if value is None or isinstance(value, str | int | float | bool):
        return value
    if isinstance(value, list | tuple):
        return [view(item) for item in value]
    if isinstance(value, ObjectView):
        return value
    return ObjectView(value)


def _attributes(target: Any) -> list[str]:
    names: list[str] = list(getattr(target, "__dict__", {}))
    for cls in type(target).__mro__:
        slots = cls.__dict__.get("__slots__", ())
        names.extend([slots] if isinstance(slots, str) else slots)
    return names


__all__ = ["Condition", "ExpressionError", "ObjectView", "view"]
