"""ROS 2 message, service and action types, from rosbags plus our own interface files.

:class:`MessageTypes` starts from rosbags' ROS 2 Jazzy type store (std_msgs, geometry_msgs,
sensor_msgs, nav_msgs, action_msgs, ...) and adds every ``.msg``, ``.srv`` and ``.action`` file
found under interface folders laid out as ROS packages (``<package>/msg/Name.msg``). The folder
bundled with cyborg holds ``cyborg_msgs`` and the few standard services rosbags lacks
(``std_srvs``, ``example_interfaces``). Like ROS, it registers for a service ``pkg/srv/X`` the
messages ``X_Request``, ``X_Response`` and ``X_Event``, and for an action ``pkg/action/X`` the
goal, result and feedback messages plus the ``SendGoal`` and ``GetResult`` services and the
``FeedbackMessage``.

    types = MessageTypes()
    raw = types.serialize(message, "std_msgs/msg/String")     # CDR, little endian
    message = types.deserialize(raw, "std_msgs/msg/String")   # numpy arrays are views on raw
    types.hash("std_srvs/srv/SetBool")                         # "RIHS01_abe9e4bb..."

Every message class is a static dataclass that mypy knows: rosbags' own for its standard types,
and for the bundled interfaces the classes generated into :mod:`cyborg.bus.msgs`
(``python3 -m cyborg.bus.codegen``), which replace the ones rosbags would make at run time.
Import them from there (:mod:`cyborg.bus.typed`); :meth:`MessageTypes.message_class` returns
those very classes, so decoded messages are instances of them.
"""

from __future__ import annotations

import dataclasses
import importlib
import logging
import struct
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from rosbags.interfaces import Nodetype
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

from cyborg.bus.stream_copy import STREAM_MINIMUM, stream_copy
from cyborg.bus.type_hash import (
    EMPTY_STRUCT_FIELD,
    SERVICE_EVENT_INFO,
    TIME,
    UUID,
    Fields,
    action_fields,
    fields_from_rosbags,
    rihs01,
    service_fields,
)
from cyborg.bus.typed import (
    ActionType,
    ServiceType,
    action_type_name,
    message_type_name,
    service_type_name,
)

log = logging.getLogger("cyborg.bus")

BUNDLED_INTERFACES = Path(__file__).with_name("definitions")
"""The interface files shipped with cyborg (cyborg_msgs and standard services)."""

_KINDS = {"msg": 1, "srv": 2, "action": 3}  # file kind -> number of `---` separated parts


CDR_LITTLE_ENDIAN = b"\x00\x01\x00\x00"
"""The encapsulation header of little-endian plain CDR, as rmw_zenoh writes it."""

_LENGTH = struct.Struct("<I")  # a CDR sequence's element count
_SMALL_ELEMENTS = {"uint8": "<u1", "int8": "<i1", "byte": "<u1", "char": "<u1",
                   "uint16": "<u2", "int16": "<i2", "uint32": "<u4", "int32": "<i4",
                   "float32": "<f4"}
"""Sequence element types whose elements follow the sequence's length without padding."""


class InterfaceError(ValueError):
    """An interface file could not be read; the message names the file and the reason."""


@dataclass(frozen=True)
class Interface:
    """One interface file: ``pkg/msg/Name``, ``pkg/srv/Name`` or ``pkg/action/Name``."""

    name: str
    kind: str
    parts: tuple[str, ...]
    source: str


def read_interfaces(root: Path) -> list[Interface]:
    """Every interface file under ``root`` (``<package>/<msg|srv|action>/<Name>.<kind>``)."""
    found = []
    for path in sorted(root.glob("*/*/*")):
        kind = path.suffix.lstrip(".")
        if kind not in _KINDS or path.parent.name != kind:
            continue
        package = path.parent.parent.name
        text = path.read_text(encoding="utf-8")
        parts = tuple(_split_parts(text))
        if len(parts) != _KINDS[kind]:
            raise InterfaceError(f"{path}: a .{kind} file has {_KINDS[kind]} part(s) separated "
                                 f"by '---' lines, this one has {len(parts)}")
        found.append(Interface(f"{package}/{kind}/{path.stem}", kind, parts, str(path)))
    return found


def _split_parts(text: str) -> list[str]:
    parts: list[list[str]] = [[]]
    for line in text.splitlines():
        if line.strip() == "---":
            parts.append([])
        else:
            parts[-1].append(line)
    return ["\n".join(lines) + "\n" for lines in parts]


class MessageTypes:
    """A type store: rosbags' ROS 2 types plus interface folders; CDR and RIHS01 hashes."""

    def __init__(self, interface_dirs: Iterable[Path] = (BUNDLED_INTERFACES,)) -> None:
        self.store = get_typestore(Stores.ROS2_JAZZY)
        self._tails: dict[str, tuple[str, np.dtype[Any]] | None] = {}
        self._synthetic: dict[str, Fields] = {}
        self.services: set[str] = set()
        self.actions: set[str] = set()
        for folder in interface_dirs:
            self.add_interfaces(read_interfaces(folder))

    # ------------------------------------------------------------------ registration
    def add_interfaces(self, interfaces: Iterable[Interface]) -> None:
        """Register interface files (all at once, so they may refer to each other)."""
        definitions: dict[str, Any] = {}
        for interface in interfaces:
            try:
                definitions.update(self._definitions(interface))
            except Exception as exc:
                raise InterfaceError(f"{interface.source}: {exc}") from exc
        self.store.register(definitions)
        for name in definitions:
            self._use_static_class(name)

    def add_definition(self, type_name: str, text: str) -> list[str]:
        """Register a message type from its ``ros2msg`` text; the names it added.

        ``text`` is what a recording's schema holds: the type's ``.msg`` text, then each type
        it uses after a line of ``=`` and ``MSG: pkg/Type``. Types the bus already knows keep
        their own definitions (a recording's copy of ``std_msgs/Header`` changes nothing).
        Raises ValueError saying what cannot be read.
        """
        try:
            definitions = get_types_from_msg(text, type_name)
        except Exception as exc:  # rosbags raises its own parse errors
            raise ValueError(f"{type_name}: its definition cannot be read ({exc})") from None
        new = {name: value for name, value in definitions.items() if name not in self}
        for name, (_consts, fields) in new.items():
            for field_name, (kind, spec) in fields:
                used = spec if kind == Nodetype.NAME else (
                    spec[0][1] if kind in (Nodetype.ARRAY, Nodetype.SEQUENCE)
                    and spec[0][0] == Nodetype.NAME else None)
                if used is not None and used not in new and used not in self:
                    raise ValueError(f"{type_name}: field {field_name} of {name} is of type "
                                     f"{used}, defined nowhere")
        try:
            self.store.register(new)
        except Exception as exc:
            raise ValueError(f"{type_name}: its definition cannot be registered ({exc})"
                             ) from None
        return sorted(new)

    def _use_static_class(self, type_name: str) -> None:
        """Put the class generated for ``type_name`` in place of the one rosbags just made.

        Only if :mod:`cyborg.bus.msgs` has one and it matches field for field. The module is
        found by the type's name: this runs for whatever interface files were read.
        """
        package, kind, short = type_name.split("/")
        try:
            module = importlib.import_module(f"cyborg.bus.msgs.{package}.{kind}")
        except ModuleNotFoundError:
            return
        static = getattr(module, f"{package}__{kind}__{short}", None)
        if static is None or getattr(static, "__msgtype__", None) != type_name:
            return
        made = self.store.types[type_name]
        if made is static:
            return
        if _shape(static) != _shape(made):
            log.warning("%s in cyborg.bus.msgs differs from its interface file; using the "
                        "file's (run `python3 -m cyborg.bus.codegen` to regenerate)", type_name)
            return
        self.store.types[type_name] = static
        self.store.cache.pop(type_name, None)

    def _definitions(self, interface: Interface) -> dict[str, Any]:
        name, parts = interface.name, interface.parts
        package = name.split("/", 1)[0]
        if interface.kind == "msg":
            return {name: self._parse(parts[0], name, package)}
        if interface.kind == "srv":
            self.services.add(name)
            return self._service(name, self._parse(parts[0], f"{name}_Request", package),
                                 self._parse(parts[1], f"{name}_Response", package))
        self.actions.add(name)
        goal, result, feedback = (f"{name}_Goal", f"{name}_Result", f"{name}_Feedback")
        definitions = {goal: self._parse(parts[0], goal, package),
                       result: self._parse(parts[1], result, package),
                       feedback: self._parse(parts[2], feedback, package),
                       f"{name}_FeedbackMessage": _struct(("goal_id", _name(UUID)),
                                                          ("feedback", _name(feedback)))}
        definitions.update(self._service(
            f"{name}_SendGoal",
            _struct(("goal_id", _name(UUID)), ("goal", _name(goal))),
            _struct(("accepted", _base("bool")), ("stamp", _name(TIME)))))
        definitions.update(self._service(
            f"{name}_GetResult",
            _struct(("goal_id", _name(UUID))),
            _struct(("status", _base("int8")), ("result", _name(result)))))
        self._synthetic.update(action_fields(name))
        return definitions

    def _service(self, name: str, request: Any, response: Any) -> dict[str, Any]:
        self._synthetic.update({name: service_fields(name)[name]})
        # X_Event carries the request and the response as sequences bounded to one element.
        event = _struct(("info", _name(SERVICE_EVENT_INFO)),
                        ("request", (Nodetype.SEQUENCE, (_name(f"{name}_Request"), 1))),
                        ("response", (Nodetype.SEQUENCE, (_name(f"{name}_Response"), 1))))
        return {f"{name}_Request": request, f"{name}_Response": response,
                f"{name}_Event": event}

    @staticmethod
    def _parse(text: str, name: str, package: str) -> Any:
        """The rosbags definition of one message part; unqualified names resolve to ``package``."""
        as_message = f"{package}/msg/{name.rsplit('/', 1)[-1]}"
        consts, fields = get_types_from_msg(text, as_message)[as_message]
        if not fields:  # ROS gives an empty struct one uint8 member, on the wire too
            fields = [(EMPTY_STRUCT_FIELD, (Nodetype.BASE, ("uint8", 0)))]
        for field_name, (_kind, spec) in fields:
            if isinstance(spec, str) and spec.endswith("/wstring"):
                raise InterfaceError(f"field {field_name!r} of {name}: wstring is not supported")
        return consts, fields

    # ------------------------------------------------------------------ queries
    def __contains__(self, type_name: object) -> bool:
        return type_name in self.store.fielddefs or type_name in self._synthetic

    def names(self) -> list[str]:
        """Every registered message type, plus service and action names."""
        return sorted({*self.store.fielddefs, *self.services, *self.actions})

    def fields(self, type_name: str) -> Fields:
        """A type's fields in type-hash form (synthetic service and action types included)."""
        synthetic = self._synthetic.get(type_name)
        if synthetic is not None:
            return synthetic
        try:
            return fields_from_rosbags(self.store.fielddefs[type_name][1])
        except KeyError:
            raise KeyError(f"unknown type {type_name!r}") from None

    def hash(self, type_name: str) -> str:
        """The RIHS01 type hash of a message, service or action, as in rmw_zenoh's keys."""
        return rihs01(type_name, self.fields)

    def message_class(self, type_name: str) -> type:
        """The Python class (a dataclass) for a message type given by name; KeyError if unknown.

        For a type known only at run time (the command line, a definition's field, an endpoint
        made from a name). Where the type is fixed, import its class from
        :mod:`cyborg.bus.msgs` instead: it is the same class, and mypy knows it.
        """
        try:
            cls: type = self.store.types[type_name]
        except KeyError:
            raise KeyError(f"unknown message type {type_name!r}") from None
        return cls

    def type_name(self, message_type: type[Any] | str) -> str:
        """The type name of ``message_type``, given by name or as a class.

        A class must be this store's own (from :mod:`cyborg.bus.msgs`), or TypeError.
        """
        name = message_type_name(message_type)
        if not isinstance(message_type, str) and self.store.types.get(name) is not message_type:
            raise TypeError(f"{message_type!r} is not the class of {name} here; import message "
                            "classes from cyborg.bus.msgs")
        return name

    def service_name(self, service_type: ServiceType[Any, Any] | str) -> str:
        """The name of a service type, given by name or as a :class:`~cyborg.bus.typed.ServiceType`.

        A ServiceType's classes must be this store's own, or TypeError.
        """
        name = service_type_name(service_type)
        if isinstance(service_type, ServiceType):
            self.type_name(service_type.Request)
            self.type_name(service_type.Response)
        return name

    def action_name(self, action_type: ActionType[Any, Any, Any] | str) -> str:
        """The name of an action type, given by name or as an :class:`~cyborg.bus.typed.ActionType`.

        An ActionType's classes must be this store's own, or TypeError.
        """
        name = action_type_name(action_type)
        if isinstance(action_type, ActionType):
            for part in (action_type.Goal, action_type.Result, action_type.Feedback):
                self.type_name(part)
        return name

    def serialize(self, message: Any, type_name: str) -> memoryview:
        """CDR bytes (little endian, with the 4-byte encapsulation header)."""
        data: memoryview = self.store.serialize_cdr(message, type_name, little_endian=True)
        return data

    def cdr_size(self, message: Any, type_name: str) -> int:
        """The length of ``message`` in CDR, header included, without serialising it."""
        size: int = 4 + self.store.get_msgdef(type_name).getsize_cdr(0, message, self.store)
        return size

    def serialize_into(self, message: Any, type_name: str, buffer: memoryview) -> int:
        """Write the CDR of ``message`` into ``buffer`` (e.g. shared memory); returns its length.

        ``buffer`` must hold :meth:`cdr_size` bytes. This is the one copy a large message costs
        on its way to another process.
        """
        msgdef = self.store.get_msgdef(type_name)
        buffer[0:4] = CDR_LITTLE_ENDIAN
        tail = self._large_tail(message, type_name)
        if tail is None:
            end: int = msgdef.serialize_cdr_le(buffer[4:], 0, message, self.store)
            return end + 4
        # The big array (an image's pixels) is the last field: serialise the rest with the
        # array empty, which ends in the sequence's length, then put the real length and
        # stream the elements after it (aligned already: elements are at most 4 bytes).
        name, array = tail
        end = 4 + msgdef.serialize_cdr_le(
            buffer[4:], 0, dataclasses.replace(message, **{name: array[:0]}), self.store)
        _LENGTH.pack_into(buffer, end - _LENGTH.size, array.size)
        stream_copy(buffer[end:end + array.nbytes], array)
        return end + array.nbytes

    def _tail_field(self, type_name: str) -> tuple[str, np.dtype[Any]] | None:
        """The last field's name and element type if it is a sequence of small numbers."""
        fields: list[tuple[str, Any]] = self.store.fielddefs[type_name][1]
        if not fields:
            return None
        name, (kind, detail) = fields[-1]
        if kind != Nodetype.SEQUENCE or detail[0][0] != Nodetype.BASE:
            return None
        element: str = detail[0][1][0]
        return (name, np.dtype(_SMALL_ELEMENTS[element])) if element in _SMALL_ELEMENTS else None

    def _large_tail(self, message: Any, type_name: str) -> tuple[str, np.ndarray] | None:
        """The last field's name and value if it is a large sequence of small numbers.

        Only when it is held as a contiguous native array; None otherwise.
        """
        if type_name not in self._tails:
            self._tails[type_name] = self._tail_field(type_name)
        described = self._tails[type_name]
        if described is None:
            return None
        name, dtype = described
        array = getattr(message, name)
        if not isinstance(array, np.ndarray) or array.dtype != dtype or array.ndim != 1 \
                or array.nbytes < STREAM_MINIMUM or not array.flags.c_contiguous:
            return None
        return name, array

    def deserialize(self, data: bytes | bytearray | memoryview, type_name: str) -> Any:
        """A message from CDR bytes; primitive arrays are read-only numpy views on ``data``.

        Nothing is copied, and because the views are read-only, one receiver of a buffer
        cannot change what another receiver of the same buffer sees.
        """
        return self.store.deserialize_cdr(memoryview(data).toreadonly(), type_name)


def _shape(message_class: type) -> list[tuple[str, object, object]]:
    """A message class's dataclass fields (constants included): name, annotation, default."""
    return [(field.name, field.type, field.default)
            for field in dataclasses.fields(message_class)]


def _base(type_name: str) -> tuple[Nodetype, tuple[str, int]]:
    return (Nodetype.BASE, (type_name, 0))


def _name(type_name: str) -> tuple[Nodetype, str]:
    return (Nodetype.NAME, type_name)


def _struct(*fields: tuple[str, Any]) -> tuple[list[Any], list[tuple[str, Any]]]:
    return [], list(fields)
