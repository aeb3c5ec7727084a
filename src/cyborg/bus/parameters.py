"""Node parameters, readable and settable at runtime — the successor of dynamic_reconfigure.

Parameters are served with ROS 2's parameter services (``<node>/list_parameters``,
``get_parameters``, ``set_parameters``, ``set_parameters_atomically``, ``describe_parameters``,
``get_parameter_types``), so ``cyborg param`` and ``ros2 param`` both work on them.

    threshold = node.parameters.declare("confidence_threshold", 0.5,
                                        "detections below this are dropped", limits=(0.0, 1.0))
    node.parameters.on_set(check)       # check(changes) raises ValueError to refuse a change
    node.parameters.on_change(apply)    # apply(changes) after a change was accepted
    node.parameters["confidence_threshold"]

A parameter's type is fixed by its default; an integer is accepted for a float parameter.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from cyborg.bus.msgs.rcl_interfaces.msg import (
    FloatingPointRange,
    IntegerRange,
    ListParametersResult,
    ParameterDescriptor,
    ParameterValue,
    SetParametersResult,
)
from cyborg.bus.msgs.rcl_interfaces.srv import (
    DescribeParameters,
    DescribeParameters_Request,
    DescribeParameters_Response,
    GetParameters,
    GetParameters_Request,
    GetParameters_Response,
    GetParameterTypes,
    GetParameterTypes_Request,
    GetParameterTypes_Response,
    ListParameters,
    ListParameters_Request,
    ListParameters_Response,
    SetParameters,
    SetParameters_Request,
    SetParameters_Response,
    SetParametersAtomically,
    SetParametersAtomically_Request,
    SetParametersAtomically_Response,
)

if TYPE_CHECKING:
    from cyborg.bus.node import Node

NOT_SET, BOOL, INTEGER, DOUBLE, STRING = 0, 1, 2, 3, 4
BYTE_ARRAY, BOOL_ARRAY, INTEGER_ARRAY, DOUBLE_ARRAY, STRING_ARRAY = 5, 6, 7, 8, 9
TYPE_NAMES = {NOT_SET: "not set", BOOL: "bool", INTEGER: "integer", DOUBLE: "double",
              STRING: "string", BYTE_ARRAY: "byte array", BOOL_ARRAY: "bool array",
              INTEGER_ARRAY: "integer array", DOUBLE_ARRAY: "double array",
              STRING_ARRAY: "string array"}
_FIELDS = {BOOL: "bool_value", INTEGER: "integer_value", DOUBLE: "double_value",
           STRING: "string_value", BYTE_ARRAY: "byte_array_value",
           BOOL_ARRAY: "bool_array_value", INTEGER_ARRAY: "integer_array_value",
           DOUBLE_ARRAY: "double_array_value", STRING_ARRAY: "string_array_value"}
_ARRAYS = {BYTE_ARRAY: np.uint8, BOOL_ARRAY: np.bool_, INTEGER_ARRAY: np.int64,
           DOUBLE_ARRAY: np.float64}

Changes = dict[str, Any]


def type_of(value: Any) -> int:
    """The ParameterType of a Python value; ValueError for values parameters cannot hold."""
    if value is None:
        return NOT_SET
    for python_type, code in ((bool, BOOL), (int, INTEGER), (float, DOUBLE), (str, STRING),
                              (bytes, BYTE_ARRAY)):
        if isinstance(value, python_type):
            return code
    if isinstance(value, list | tuple):
        for element_type, code in ((bool, BOOL_ARRAY), (int, INTEGER_ARRAY),
                                   (float, DOUBLE_ARRAY), (str, STRING_ARRAY)):
            if value and all(isinstance(item, element_type) for item in value):
                return code
        if value and all(isinstance(item, int | float) and not isinstance(item, bool)
                         for item in value):
            return DOUBLE_ARRAY
    raise ValueError(f"{value!r} cannot be a parameter value (bool, int, float, str, bytes "
                     "or a list of one of them)")


def to_message(value: Any, kind: int | None = None) -> ParameterValue:
    """A Python value as ``rcl_interfaces/msg/ParameterValue`` (``kind`` for empty lists).

    Raises ValueError for a value no parameter can hold (see :func:`type_of`).
    """
    code = type_of(value) if kind is None else kind
    fields: dict[str, Any] = {"type": code, "bool_value": False, "integer_value": 0,
                              "double_value": 0.0, "string_value": "",
                              "string_array_value": []}
    for array_code, dtype in _ARRAYS.items():
        fields[_FIELDS[array_code]] = np.array([], dtype=dtype)
    if code in _ARRAYS:
        fields[_FIELDS[code]] = np.array(list(value), dtype=_ARRAYS[code])
    elif code == STRING_ARRAY:
        fields[_FIELDS[code]] = list(value)
    elif code != NOT_SET:
        fields[_FIELDS[code]] = value
    return ParameterValue(**fields)


def from_message(message: Any) -> Any:
    """A ``ParameterValue`` as a Python value (arrays as lists, byte arrays as bytes)."""
    code = int(message.type)
    if code == NOT_SET:
        return None
    if code not in _FIELDS:
        raise ValueError(f"unknown parameter type {code}")
    value = getattr(message, _FIELDS[code])
    if code == BYTE_ARRAY:
        return bytes(value)
    return value.tolist() if isinstance(value, np.ndarray) else (
        list(value) if code == STRING_ARRAY else value)


@dataclass
class Declared:
    """One declared parameter: its value now and what was declared with it."""

    name: str
    value: Any
    description: str = ""
    read_only: bool = False
    limits: tuple[float, float] | None = None
    """Lowest and highest value of a number parameter, inclusive; None: any."""
    kind: int = NOT_SET
    """The ParameterType, fixed by the default (an empty list can be any array type)."""


class Parameters:
    """A node's parameters and the services that expose them."""

    def __init__(self, node: Node, overrides: dict[str, Any]) -> None:
        self._node = node
        self._declared: dict[str, Declared] = {}
        self._overrides = dict(overrides)
        self._checks: list[Callable[[Changes], object]] = []
        self._listeners: list[Callable[[Changes], object]] = []
        self._lock = threading.RLock()
        prefix = f"{node.fq_name}/"
        node.create_service(prefix + "list_parameters", ListParameters, self._list)
        node.create_service(prefix + "get_parameters", GetParameters, self._get)
        node.create_service(prefix + "set_parameters", SetParameters, self._set)
        node.create_service(prefix + "set_parameters_atomically", SetParametersAtomically,
                            self._set_atomically)
        node.create_service(prefix + "describe_parameters", DescribeParameters, self._describe)
        node.create_service(prefix + "get_parameter_types", GetParameterTypes, self._get_types)

    # ------------------------------------------------------------------ Python API
    def declare(self, name: str, default: Any, description: str = "", *,
                read_only: bool = False, limits: tuple[float, float] | None = None) -> Any:
        """Declare a parameter; a value given at start-up (``Node(parameters=...)``) wins."""
        with self._lock:
            if name in self._declared:
                raise ValueError(f"parameter {name!r} of {self._node.fq_name} is already "
                                 "declared")
            if isinstance(default, list | tuple) and not default:
                raise ValueError(f"parameter {name!r}: an empty list default has no type; "
                                 "give one item")
            declared = Declared(name, default, description, read_only, limits, type_of(default))
            if name in self._overrides:
                declared.value = self._checked(declared, self._overrides.pop(name))
            self._declared[name] = declared
            return declared.value

    def __getitem__(self, name: str) -> Any:
        with self._lock:
            try:
                return self._declared[name].value
            except KeyError:
                raise KeyError(f"{self._node.fq_name} has no parameter {name!r}") from None

    def __contains__(self, name: object) -> bool:
        return name in self._declared

    def names(self) -> list[str]:
        """The declared parameters' names, sorted."""
        return sorted(self._declared)

    def on_set(self, check: Callable[[Changes], object]) -> None:
        """``check(changes)`` runs before a change; raising ValueError refuses it."""
        self._checks.append(check)

    def on_change(self, listener: Callable[[Changes], object]) -> None:
        """``listener(changes)`` runs after a change was accepted."""
        self._listeners.append(listener)

    def set(self, changes: Changes) -> None:
        """Set several parameters at once, all or none; ValueError says why not."""
        with self._lock:
            checked: Changes = {}
            for name, value in changes.items():
                declared = self._declared.get(name)
                if declared is None:
                    raise ValueError(f"{self._node.fq_name} has no parameter {name!r}")
                if declared.read_only:
                    raise ValueError(f"parameter {name!r} is read-only")
                checked[name] = self._checked(declared, value)
            for check in self._checks:
                check(dict(checked))
            for name, value in checked.items():
                self._declared[name].value = value
        for listener in self._listeners:
            self._node.callbacks.call(listener, dict(checked))

    def _checked(self, declared: Declared, value: Any) -> Any:
        wanted = declared.kind
        if isinstance(value, list | tuple) and not value and wanted in (*_ARRAYS, STRING_ARRAY):
            return []
        given = type_of(value)
        if wanted == DOUBLE and given == INTEGER:
            value, given = float(value), DOUBLE
        if wanted == DOUBLE_ARRAY and given == INTEGER_ARRAY:
            value, given = [float(v) for v in value], DOUBLE_ARRAY
        if wanted != NOT_SET and given != wanted:
            raise ValueError(f"parameter {declared.name!r} is a {TYPE_NAMES[wanted]}, "
                             f"not a {TYPE_NAMES[given]} ({value!r})")
        if declared.limits is not None and given in (INTEGER, DOUBLE):
            low, high = declared.limits
            if not low <= value <= high:
                raise ValueError(f"parameter {declared.name!r}: {value} is outside "
                                 f"[{low:g}, {high:g}]")
        return list(value) if isinstance(value, tuple) else value

    # ------------------------------------------------------------------ services
    @staticmethod
    def _result(error: str | None) -> SetParametersResult:
        return SetParametersResult(successful=error is None, reason=error or "")

    def _list(self, request: ListParameters_Request) -> ListParameters_Response:
        prefixes: Sequence[str] = request.prefixes
        names = [n for n in self.names() if not prefixes or any(
            n == p or n.startswith(p + ".") for p in prefixes)]
        result = ListParametersResult(
            names=names, prefixes=sorted({n.rsplit(".", 1)[0] for n in names if "." in n}))
        return ListParameters.Response(result=result)

    def _get(self, request: GetParameters_Request) -> GetParameters_Response:
        values = [to_message(self._declared[n].value, self._declared[n].kind)
                  if n in self._declared else to_message(None)
                  for n in request.names]
        return GetParameters.Response(values=values)

    def _get_types(self, request: GetParameterTypes_Request) -> GetParameterTypes_Response:
        codes = [self._declared[n].kind if n in self._declared else NOT_SET
                 for n in request.names]
        return GetParameterTypes.Response(types=np.array(codes, dtype=np.uint8))

    def _set(self, request: SetParameters_Request) -> SetParameters_Response:
        """One result per parameter, in order, each set on its own.

        A value that cannot be read is refused in its result (as a wrong type is), never raised.
        """
        results = []
        for parameter in request.parameters:
            try:
                error = self._try_set({parameter.name: from_message(parameter.value)})
            except ValueError as exc:
                error = f"parameter {parameter.name!r}: {exc}"
            results.append(self._result(error))
        return SetParameters.Response(results=results)

    def _set_atomically(self, request: SetParametersAtomically_Request
                        ) -> SetParametersAtomically_Response:
        try:
            changes = {p.name: from_message(p.value) for p in request.parameters}
        except ValueError as exc:
            error: str | None = str(exc)
        else:
            error = self._try_set(changes)
        return SetParametersAtomically.Response(result=self._result(error))

    def _try_set(self, changes: Changes) -> str | None:
        try:
            self.set(changes)
        except ValueError as exc:
            return str(exc)
        return None

    def _describe(self, request: DescribeParameters_Request) -> DescribeParameters_Response:
        descriptors = []
        for name in request.names:
            declared = self._declared.get(name, Declared(name, None))
            code = declared.kind
            floats, integers = [], []
            if declared.limits and code == DOUBLE:
                floats = [FloatingPointRange(from_value=float(declared.limits[0]),
                                       to_value=float(declared.limits[1]), step=0.0)]
            if declared.limits and code == INTEGER:
                integers = [IntegerRange(from_value=int(declared.limits[0]),
                                          to_value=int(declared.limits[1]), step=0)]
            descriptors.append(ParameterDescriptor(
                name=name, type=code, description=declared.description,
                additional_constraints="", read_only=declared.read_only, dynamic_typing=False,
                floating_point_range=floats, integer_range=integers))
        return DescribeParameters.Response(descriptors=descriptors)
