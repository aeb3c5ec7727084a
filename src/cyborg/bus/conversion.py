"""Messages to and from plain Python data (dicts, lists, numbers), e.g. for the command line.

    new_message(types, "geometry_msgs/msg/Twist", {"linear": {"x": 0.2}})
    to_plain(message)          # {"linear": {"x": 0.2, "y": 0.0, "z": 0.0}, "angular": {...}}

Fields left out get their zero value, as in ROS. A field the type does not have, or a value of
the wrong kind, raises :class:`MessageValueError` naming the field path (``linear.x``).
Constants of a type (``BatteryState.POWER_SUPPLY_STATUS_FULL``) are not fields: ``to_plain``
leaves them out, as ``ros2 topic echo`` does.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np
from rosbags.interfaces import Nodetype

from cyborg.bus.message_types import MessageTypes

_NUMPY = {"bool": np.bool_, "byte": np.uint8, "char": np.uint8, "int8": np.int8,
          "uint8": np.uint8, "int16": np.int16, "uint16": np.uint16, "int32": np.int32,
          "uint32": np.uint32, "int64": np.int64, "uint64": np.uint64, "float32": np.float32,
          "float64": np.float64}
_INTEGER_BITS = {"int8": 8, "int16": 16, "int32": 32, "int64": 64, "uint8": 8, "uint16": 16,
                 "uint32": 32, "uint64": 64, "byte": 8, "char": 8}


class MessageValueError(ValueError):
    """Plain data that does not fit a message type; the message names the field."""


def to_plain(message: Any) -> Any:
    """A message as nested dicts and lists (numpy arrays become lists), fields only."""
    if isinstance(message, np.ndarray):
        return message.tolist()
    if isinstance(message, list):
        return [to_plain(item) for item in message]
    if dataclasses.is_dataclass(message) and not isinstance(message, type):
        return {name: to_plain(getattr(message, name)) for name in message_fields(type(message))}
    return message


def message_fields(message_class: type) -> list[str]:
    """The names of a message class's fields, in order, without its constants.

    rosbags writes each constant (and ``__msgtype__``) as ``NAME: ClassVar[int] = 1`` in a
    module whose annotations stay strings, and :mod:`dataclasses` only recognises a string
    ``ClassVar`` when ``typing`` is imported there under that name. So the constants come back
    from :func:`dataclasses.fields` as ordinary fields with defaults. A real field of a message
    is never a ``ClassVar``, which is how they are told apart here.
    """
    return [field.name for field in dataclasses.fields(message_class)
            if not (isinstance(field.type, str)
                    and field.type.startswith(("ClassVar", "typing.ClassVar")))]


def new_message(types: MessageTypes, type_name: str, data: dict[str, Any] | None = None,
                *, path: str = "") -> Any:
    """A message of ``type_name`` built from ``data``; missing fields get zero values."""
    data = {} if data is None else data
    if not isinstance(data, dict):
        raise MessageValueError(f"{path or type_name}: expected a mapping of fields, "
                                f"got {data!r}")
    fields = types.store.fielddefs[type_name][1]
    known = {name for name, _ in fields}
    for name in data:
        if name not in known:
            raise MessageValueError(f"{_join(path, name)}: {type_name} has no such field "
                                    f"(fields: {', '.join(sorted(known))})")
    values = {name: _value(types, spec, data.get(name), _join(path, name))
              for name, spec in fields}
    # by name: the type is chosen at run time (the command line, a field's definition)
    return types.message_class(type_name)(**values)


def _join(path: str, name: str) -> str:
    return f"{path}.{name}" if path else name


def _value(types: MessageTypes, spec: tuple[Any, Any], value: Any, path: str) -> Any:
    kind, detail = spec
    if kind == Nodetype.NAME:
        return new_message(types, detail, value, path=path)
    if kind == Nodetype.BASE:
        return _base(detail[0], value, path)
    (element_kind, element), bound = detail
    items = [] if value is None else value
    if not isinstance(items, list | tuple | np.ndarray):
        raise MessageValueError(f"{path}: expected a list, got {value!r}")
    if kind == Nodetype.ARRAY and value is None:
        items = [None] * bound
    if kind == Nodetype.ARRAY and len(items) != bound:
        raise MessageValueError(f"{path}: expected {bound} items, got {len(items)}")
    if kind == Nodetype.SEQUENCE and bound and len(items) > bound:
        raise MessageValueError(f"{path}: at most {bound} items, got {len(items)}")
    converted = [_value(types, (element_kind, element), item, f"{path}[{i}]")
                 for i, item in enumerate(items)]
    if element_kind == Nodetype.BASE and element[0] in _NUMPY:
        return np.array(converted, dtype=_NUMPY[element[0]])
    return converted


def _base(type_name: str, value: Any, path: str) -> Any:
    if type_name == "string":
        if value is None:
            return ""
        if not isinstance(value, str):
            raise MessageValueError(f"{path}: expected text, got {value!r}")
        return value
    if type_name == "bool":
        if value is None:
            return False
        if not isinstance(value, bool | np.bool_):
            raise MessageValueError(f"{path}: expected true or false, got {value!r}")
        return bool(value)
    if type_name in ("float32", "float64"):
        if value is None:
            return 0.0
        if isinstance(value, bool) or not isinstance(value, int | float | np.number):
            raise MessageValueError(f"{path}: expected a number, got {value!r}")
        return float(value)
    if value is None:
        return 0
    if isinstance(value, bool) or not isinstance(value, int | np.integer):
        raise MessageValueError(f"{path}: expected an integer, got {value!r}")
    bits = _INTEGER_BITS.get(type_name, 64)
    low, high = (0, 2**bits - 1) if type_name.startswith("u") or type_name in (
        "byte", "char") else (-(2 ** (bits - 1)), 2 ** (bits - 1) - 1)
    if not low <= int(value) <= high:
        raise MessageValueError(f"{path}: {value} is out of range for {type_name}")
    return int(value)
