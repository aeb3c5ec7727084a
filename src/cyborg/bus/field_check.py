"""Where a message does not fit its type, named by field, in one line.

A service's client checks a request before sending it and its server checks a response
before replying (:mod:`cyborg.bus.services`); both need the first wrong field, however
deep, in words a person reads at a terminal::

    field_problem(types, "geometry_msgs/msg/Pose2D", pose)   # "x: expected a number, got '1'"

and every text that crosses between processes is one printable line (:func:`one_line`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from rosbags.interfaces import Nodetype

if TYPE_CHECKING:
    from cyborg.bus.message_types import MessageTypes

MAX_ERROR_TEXT = 300
"""Characters of an error text that travel between a server and its caller."""


def one_line(text: str, limit: int = MAX_ERROR_TEXT) -> str:
    """The first line of ``text``, control characters escaped, at most ``limit`` characters.

    That is what may travel between a server and a caller's terminal (never a traceback).
    """
    first = text.strip().split("\n", 1)[0].strip()
    first = "".join(char if char.isprintable() else f"\\x{ord(char):02x}"
                    if ord(char) < 256 else f"\\u{ord(char):04x}" for char in first)
    return first if len(first) <= limit else first[: limit - 1] + "…"


def field_problem(types: MessageTypes, type_name: str, message: Any,
                  path: str = "") -> str | None:
    """Where ``message`` does not fit ``type_name``; None where it fits.

    Names the first field that is wrong, however deep: ``"goal.x: expected a number, got '1'"``.
    """
    # by name: the type of each nested field is known only from the definition, at run time
    if not isinstance(message, types.message_class(type_name)):
        return f"{path or 'the message'}: expected a {type_name}, got {_shown(message)}"
    for name, (kind, detail) in types.store.fielddefs[type_name][1]:
        where = f"{path}.{name}" if path else name
        problem = _value_problem(types, kind, detail, getattr(message, name, None), where)
        if problem:
            return problem
    return None


def _value_problem(types: MessageTypes, kind: Any, detail: Any, value: Any,
                   where: str) -> str | None:
    if kind == Nodetype.NAME:
        return field_problem(types, detail, value, where)
    if kind == Nodetype.BASE:
        return _base_problem(detail[0], value, where)
    (element_kind, element), bound = detail
    if not isinstance(value, list | tuple | np.ndarray):
        return f"{where}: expected a list, got {_shown(value)}"
    if kind == Nodetype.ARRAY and len(value) != bound:
        return f"{where}: expected {bound} items, got {len(value)}"
    if kind == Nodetype.SEQUENCE and bound and len(value) > bound:
        return f"{where}: at most {bound} items, got {len(value)}"
    if isinstance(value, np.ndarray) and value.dtype != object:
        return None  # numbers: the serialiser converts the array as a whole
    for index, item in enumerate(value):
        problem = _value_problem(types, element_kind, element, item, f"{where}[{index}]")
        if problem:
            return problem
    return None


def _base_problem(type_name: str, value: Any, where: str) -> str | None:
    if type_name in ("string", "wstring"):
        if not isinstance(value, str):
            return f"{where}: expected text, got {_shown(value)}"
        try:
            value.encode("utf-8")
        except UnicodeEncodeError as exc:
            return f"{where}: not valid text (a lone surrogate at character {exc.start})"
        return None
    if type_name == "bool":
        ok = isinstance(value, bool | np.bool_)
        return None if ok else f"{where}: expected true or false, got {_shown(value)}"
    if type_name in ("float32", "float64"):
        ok = isinstance(value, int | float | np.number) and not isinstance(value, bool)
        return None if ok else f"{where}: expected a number, got {_shown(value)}"
    ok = isinstance(value, int | np.integer) and not isinstance(value, bool)
    return None if ok else f"{where}: expected an integer ({type_name}), got {_shown(value)}"


def _shown(value: Any) -> str:
    text = repr(value)
    return one_line(text if len(text) <= 40 else text[:39] + "…")
