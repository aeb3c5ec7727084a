"""Node properties: from the editor's JSON to a node's keyword arguments.

A node declares its properties as the keyword parameters of its ``__init__``, with type hints::

    class MoveTo(Action):
        def __init__(self, location: str, radius: float = 0.5) -> None: ...

The editor writes property names in camelCase (``maxLoop``); Python parameters are snake_case
(``max_loop``). Both spellings are accepted. Values are checked against the hints:

* ``int`` takes whole numbers (``2.0`` becomes ``2``), ``float`` takes any number, ``bool`` takes
  ``true``/``false``; a string holding a number or boolean is converted, because the editor's
  property panel lets users type numbers as text;
* numbers must be **finite**: NaN is always refused (a NaN ``milliseconds`` made Wait run
  forever, as every comparison with NaN is false), and so are ``inf``/``-inf`` (``Infinity``,
  ``1e400``, ``"inf"``) and whole numbers too large for a float, except where the node says it
  means infinity: a ``float`` parameter whose *default* is infinite (``below: float =
  math.inf``, "no limit") also takes either infinity. A whole number of any size fits an
  ``int`` parameter;
* a count whose hint is annotated :class:`Unbounded` (``Annotated[int, Unbounded(-1)]``, the
  :data:`LoopCount` of the repeating decorators) also takes positive infinity, and gets the
  value that means "no end" instead, with a note: behavior3js loops ``while (i < maxLoop)``,
  so a ``maxLoop`` of ``1e999`` (how JSON writes infinity) runs forever;
* ``str``, ``Literal[...]``, ``Enum`` (by value or name), ``X | None``, ``list[X]``,
  ``dict[str, X]`` and ``Any`` are supported; other hints are passed through unchecked.

A required parameter with no property is an error; a property no parameter takes is a warning
(the editor lets users annotate any node), unless the node accepts ``**kwargs``.
"""

from __future__ import annotations

import inspect
import json
import math
import re
import types
import typing
from dataclasses import dataclass, field
from enum import Enum
from typing import Annotated, Any, Literal, Union

from cyborg.bt.problems import shown

_MISSING = inspect.Parameter.empty


@dataclass(frozen=True)
class Unbounded:
    """Marks a count parameter in which positive infinity means "no end" (see the module)."""

    means: Any
    """The value the node takes for "no end" (``-1``, or ``None``)."""


LoopCount = Annotated[int, Unbounded(-1)]
"""A number of loops, ``-1`` for forever; infinity in a file is read as ``-1``."""
OptionalLoopCount = Annotated[int | None, Unbounded(None)]
"""A number of runs or tries, none for no end (behavior3 v1's); infinity is read as none."""


@dataclass(frozen=True)
class Param:
    """One property a node type takes."""

    name: str
    """The Python keyword (``max_loop``)."""
    editor_name: str
    """The camelCase name the editor uses (``maxLoop``)."""
    hint: Any
    default: Any = _MISSING
    unbounded: Unbounded | None = None
    """Set when infinity stands for this count's "no end" value."""

    @property
    def required(self) -> bool:
        """Whether the file must give the property: the keyword has no default."""
        return self.default is _MISSING

    @property
    def allows_infinity(self) -> bool:
        """Whether the node declared infinity a meaningful value: its default is infinite."""
        return isinstance(self.default, float) and math.isinf(self.default)


@dataclass(frozen=True)
class Signature:
    """The properties a node type takes, read from its ``__init__``."""

    params: tuple[Param, ...]
    takes_any: bool
    """True when ``__init__`` has ``**kwargs``: unknown properties are passed through."""

    def defaults(self) -> dict[str, Any]:
        """The editor-named defaults, as they would appear in a ``custom_nodes`` entry."""
        return {p.editor_name: p.default for p in self.params if not p.required}


@dataclass(frozen=True)
class Binding:
    """The result of matching a node's properties to its signature."""

    kwargs: dict[str, Any]
    errors: list[tuple[str, str]]
    """(field, message) pairs that stop the node from being built."""
    warnings: list[tuple[str, str]]
    notes: list[tuple[str, str]] = field(default_factory=list)
    """(field, message) pairs that say how a value was read, such as infinity as "forever"."""


def snake_case(name: str) -> str:
    """``maxLoop`` -> ``max_loop``; ``successThreshold`` -> ``success_threshold``."""
    return re.sub(r"(?<=[a-z0-9])([A-Z])", r"_\1", name).lower()


def camel_case(name: str) -> str:
    """``max_loop`` -> ``maxLoop``."""
    head, *rest = name.split("_")
    return head + "".join(part[:1].upper() + part[1:] for part in rest)


def signature_of(factory: Any) -> Signature:
    """The properties a node class (its ``__init__``) or factory function takes."""
    target = factory.__init__ if inspect.isclass(factory) else factory
    if target is object.__init__:
        return Signature((), False)
    sig = inspect.signature(target)
    try:
        hints = typing.get_type_hints(target, include_extras=True)
    except Exception:  # unresolvable forward references: check nothing rather than fail
        hints = {}
    params = []
    takes_any = False
    for index, parameter in enumerate(sig.parameters.values()):
        if index == 0 and inspect.isclass(factory) and parameter.name in ("self", "cls"):
            continue
        if parameter.kind is inspect.Parameter.VAR_KEYWORD:
            takes_any = True
            continue
        if parameter.kind in (inspect.Parameter.VAR_POSITIONAL,
                              inspect.Parameter.POSITIONAL_ONLY):
            continue
        hint, unbounded = _unannotated(hints.get(parameter.name, Any))
        params.append(Param(parameter.name, camel_case(parameter.name), hint,
                            parameter.default, unbounded))
    return Signature(tuple(params), takes_any)


def _unannotated(hint: Any) -> tuple[Any, Unbounded | None]:
    """``hint`` without ``Annotated``, and its :class:`Unbounded` mark if it has one."""
    if typing.get_origin(hint) is not Annotated:
        return hint, None
    marks = [mark for mark in hint.__metadata__ if isinstance(mark, Unbounded)]
    return hint.__origin__, marks[0] if marks else None


def bind(signature: Signature, properties: dict[str, Any],
         file_names: dict[str, str] | None = None) -> Binding:
    """Matches editor ``properties`` against ``signature``, converting and checking each value.

    ``file_names`` name properties as the file does where a reader renamed them (a v1 Wait's
    ``milliseconds`` is the file's ``time``).
    """
    names = file_names or {}
    by_name: dict[str, Param] = {}
    for param in signature.params:
        by_name[param.name] = param
        by_name[param.editor_name] = param
    kwargs: dict[str, Any] = {}
    source: dict[str, str] = {}
    errors: list[tuple[str, str]] = []
    warnings: list[tuple[str, str]] = []
    notes: list[tuple[str, str]] = []
    for key, value in properties.items():
        match = by_name.get(key) or by_name.get(snake_case(key))
        said = names.get(key, key)  # the key as the file wrote it
        if match is None:
            if signature.takes_any:
                kwargs[key] = value
            else:
                known = ", ".join(names.get(p.editor_name, p.editor_name)
                                  for p in signature.params) or "none"
                warnings.append((said, f"unknown property {said!r} is ignored (known: {known})"))
            continue
        if match.name in source:
            errors.append((said, f"property {said!r} repeats {source[match.name]!r}"))
            continue
        source[match.name] = said
        if match.unbounded is not None and _is_positive_infinity(value):
            kwargs[match.name] = match.unbounded.means
            notes.append((said, f"property {said!r} is infinity, which behavior3js runs as no "
                                f"end: read as {json.dumps(match.unbounded.means)} (forever)"))
            continue
        try:
            kwargs[match.name] = convert(value, match.hint, infinite=match.allows_infinity)
        except ValueError as exc:
            errors.append((said, f"property {said!r}: {exc}"))
    for param in signature.params:
        if param.required and param.name not in source:
            said = names.get(param.editor_name, param.editor_name)
            errors.append((said, f"missing property {said!r} ({describe(param.hint)})"))
    return Binding(kwargs, errors, warnings, notes)


def _is_positive_infinity(value: Any) -> bool:
    """Whether ``value`` is ``inf``, or text that reads as it (``"Infinity"``, ``"1e999"``)."""
    try:
        number = _number(value, float)
    except ValueError:
        return False
    return isinstance(number, float) and math.isinf(number) and number > 0


def convert(value: Any, hint: Any, *, infinite: bool = False) -> Any:
    """``value`` checked against the type ``hint``, converted where the editor is loose.

    Numbers must be finite; ``infinite`` lets a ``float`` (at the top level, or in a union)
    be ``inf`` or ``-inf`` too. Raises ValueError with a message that names the expected type
    and the value.
    """
    if hint is Any or hint is inspect.Parameter.empty:
        return value
    origin = typing.get_origin(hint)
    if origin in (Union, types.UnionType):
        return _convert_union(value, hint, infinite)
    if origin is Literal:
        choices = typing.get_args(hint)
        if value in choices:
            return value
        raise ValueError(f"expected one of {', '.join(map(repr, choices))}, got {shown(value)}")
    if origin is list:
        return _convert_list(value, hint)
    if origin is dict:
        return _convert_dict(value, hint)
    if hint is type(None):
        if value is None:
            return None
        raise _mismatch(value, hint)
    if hint is bool:
        return _convert_bool(value)
    if hint is int:
        return _convert_int(value)
    if hint is float:
        return _convert_float(value, infinite)
    if hint is str:
        if isinstance(value, str):
            return value
        raise _mismatch(value, hint)
    if isinstance(hint, type) and issubclass(hint, Enum):
        return _convert_enum(value, hint)
    return value


def describe(hint: Any) -> str:
    """A short human name for a type hint (``int``, ``str | None``)."""
    if hint is Any or hint is inspect.Parameter.empty:
        return "any value"
    if isinstance(hint, type) and typing.get_origin(hint) is None:
        return hint.__name__
    return str(hint).replace("typing.", "")


def _mismatch(value: Any, hint: Any) -> ValueError:
    return ValueError(f"expected {describe(hint)}, got {shown(value)} ({type(value).__name__})")


def _convert_union(value: Any, hint: Any, infinite: bool) -> Any:
    reasons = []
    for option in typing.get_args(hint):
        try:
            return convert(value, option, infinite=infinite)
        except ValueError as exc:
            reasons.append(str(exc))
    finite = [reason for reason in reasons if "finite" in reason]
    raise ValueError(finite[0]) if finite else _mismatch(value, hint)


def _convert_list(value: Any, hint: Any) -> list[Any]:
    if not isinstance(value, list):
        raise _mismatch(value, hint)
    (item_hint,) = typing.get_args(hint) or (Any,)
    return [convert(item, item_hint) for item in value]


def _convert_dict(value: Any, hint: Any) -> dict[str, Any]:
    if not isinstance(value, dict):
        raise _mismatch(value, hint)
    args = typing.get_args(hint)
    value_hint = args[1] if len(args) == 2 else Any
    return {key: convert(item, value_hint) for key, item in value.items()}


def _convert_bool(value: Any) -> bool:
    if isinstance(value, bool):
        return value
    if isinstance(value, str) and value.strip().lower() in ("true", "false"):
        return value.strip().lower() == "true"
    raise _mismatch(value, bool)


def _number(value: Any, hint: type) -> float:
    if isinstance(value, bool):
        raise _mismatch(value, hint)
    if isinstance(value, int | float):
        return value
    if isinstance(value, str) and len(value) <= 100:
        try:
            return float(value.strip())
        except ValueError:
            raise _mismatch(value, hint) from None
    raise _mismatch(value, hint)


def _not_finite(value: Any, hint: type, infinite: bool) -> ValueError:
    allowed = "a finite number or infinity" if infinite else "a finite number"
    return ValueError(f"expected {allowed} ({describe(hint)}), got {shown(value)}")


def _convert_int(value: Any) -> int:
    number = _number(value, int)
    if isinstance(number, int):
        return number
    if not math.isfinite(number):
        raise _not_finite(value, int, False)
    if number != int(number):
        raise _mismatch(value, int)
    return int(number)


def _convert_float(value: Any, infinite: bool = False) -> float:
    number = _number(value, float)
    try:
        result = float(number)
    except OverflowError:  # a whole number past 1.8e308
        raise ValueError(f"expected a finite number (float), got {shown(value)}, which is too "
                         "large for one") from None
    if math.isnan(result) or (math.isinf(result) and not infinite):
        raise _not_finite(value, float, infinite)
    return result


def _convert_enum(value: Any, hint: type[Enum]) -> Enum:
    for member in hint:
        if value == member.value or (isinstance(value, str) and value == member.name):
            return member
    choices = ", ".join(repr(member.value) for member in hint)
    raise ValueError(f"expected one of {choices}, got {shown(value)}")
