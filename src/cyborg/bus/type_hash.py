"""ROS 2 type hashes (REP-2011, ``RIHS01_<sha256>``), as rmw_zenoh puts them in its keys.

The hash is the SHA-256 of a JSON description of a type and of every type it refers to:

    {"type_description": T, "referenced_type_descriptions": [R1, R2, ...]}   # R sorted by name
    T = {"type_name": "pkg/msg/Name",
         "fields": [{"name": ..., "type": {"type_id", "capacity", "string_capacity",
                                           "nested_type_name"}}, ...]}

written with ``json.dumps(..., separators=(", ", ": "))``. Constants and default values are
not part of it. Two details differ from rosbags' own ``hash_rihs01``, and this module gets them
right: a ``.msg`` ``char`` is a ``uint8`` (type id 3, not 13), and services and actions hash the
synthetic types ROS builds for them (see :func:`service_fields` and :func:`action_fields`).
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Callable, Mapping
from typing import Any

FieldType = dict[str, Any]
Fields = list[tuple[str, FieldType]]
"""A type's fields: (name, {"type_id", "capacity", "string_capacity", "nested_type_name"})."""

NESTED = 1
BOUNDED_STRING = 21
FIXED_ARRAY_OFFSET = 48
BOUNDED_SEQUENCE_OFFSET = 96
UNBOUNDED_SEQUENCE_OFFSET = 144

BASE_TYPE_IDS: Mapping[str, int] = {
    "int8": 2, "uint8": 3, "char": 3, "int16": 4, "uint16": 5, "int32": 6, "uint32": 7,
    "int64": 8, "uint64": 9, "float32": 10, "float64": 11, "float128": 12, "bool": 15,
    "byte": 16, "octet": 16, "string": 17, "wstring": 18,
}
"""``.msg`` base types to REP-2011 field type ids (``char`` maps to uint8, as rosidl does)."""

EMPTY_STRUCT_FIELD = "structure_needs_at_least_one_member"
SERVICE_EVENT_INFO = "service_msgs/msg/ServiceEventInfo"
UUID = "unique_identifier_msgs/msg/UUID"
TIME = "builtin_interfaces/msg/Time"


def field_type(type_id: int, *, capacity: int = 0, string_capacity: int = 0,
               nested: str = "") -> FieldType:
    """One field's ``type`` entry, keys in the order the hash needs."""
    return {"type_id": type_id, "capacity": capacity, "string_capacity": string_capacity,
            "nested_type_name": nested}


def nested(type_name: str) -> FieldType:
    """The ``type`` entry of a field holding one message of ``type_name``."""
    return field_type(NESTED, nested=type_name)


def fields_from_rosbags(fielddefs: list[tuple[str, Any]]) -> Fields:
    """Fields of a rosbags message definition (``typestore.fielddefs[name][1]``)."""
    fields: Fields = []
    for name, (node_type, spec) in fielddefs:
        fields.append((name, _rosbags_type(int(node_type), spec)))
    if not fields:
        fields.append((EMPTY_STRUCT_FIELD, field_type(BASE_TYPE_IDS["uint8"])))
    return fields


def _rosbags_type(node_type: int, spec: Any) -> FieldType:
    # rosbags Nodetype: BASE=1, NAME=2, ARRAY=3, SEQUENCE=4.
    if node_type == 1:
        base, bound = spec
        if base == "string" and bound:
            return field_type(BOUNDED_STRING, string_capacity=bound)
        return field_type(BASE_TYPE_IDS[base])
    if node_type == 2:
        return nested(spec)
    (inner_kind, inner_spec), size = spec
    inner = _rosbags_type(int(inner_kind), inner_spec)
    if node_type == 3:
        offset, capacity = FIXED_ARRAY_OFFSET, size
    elif size:
        offset, capacity = BOUNDED_SEQUENCE_OFFSET, size
    else:
        offset, capacity = UNBOUNDED_SEQUENCE_OFFSET, 0
    return field_type(inner["type_id"] + offset, capacity=capacity,
                      string_capacity=inner["string_capacity"],
                      nested=inner["nested_type_name"])


def service_fields(service: str) -> dict[str, Fields]:
    """The synthetic types ROS hashes for service ``pkg/srv/X``: X itself and X_Event."""
    request, response, event = f"{service}_Request", f"{service}_Response", f"{service}_Event"
    one = {"capacity": 1}
    return {
        service: [("request_message", nested(request)), ("response_message", nested(response)),
                  ("event_message", nested(event))],
        event: [("info", nested(SERVICE_EVENT_INFO)),
                ("request", field_type(NESTED + BOUNDED_SEQUENCE_OFFSET, nested=request, **one)),
                ("response", field_type(NESTED + BOUNDED_SEQUENCE_OFFSET, nested=response,
                                        **one))],
    }


def action_fields(action: str) -> dict[str, Fields]:
    """The synthetic type ROS hashes for action ``pkg/action/X``."""
    return {action: [
        ("goal", nested(f"{action}_Goal")),
        ("result", nested(f"{action}_Result")),
        ("feedback", nested(f"{action}_Feedback")),
        ("send_goal_service", nested(f"{action}_SendGoal")),
        ("get_result_service", nested(f"{action}_GetResult")),
        ("feedback_message", nested(f"{action}_FeedbackMessage")),
    ]}


def rihs01(type_name: str, fields_of: Callable[[str], Fields]) -> str:
    """The ``RIHS01_...`` hash of ``type_name``; ``fields_of`` returns any type's fields."""
    referenced: dict[str, Fields] = {}
    pending = [type_name]
    while pending:
        for _, ftype in fields_of(pending.pop()):
            name = ftype["nested_type_name"]
            if name and name not in referenced and name != type_name:
                referenced[name] = fields_of(name)
                pending.append(name)
    document = {
        "type_description": _describe(type_name, fields_of(type_name)),
        "referenced_type_descriptions": [_describe(name, referenced[name])
                                         for name in sorted(referenced)],
    }
    text = json.dumps(document, separators=(", ", ": "), sort_keys=False)
    return "RIHS01_" + hashlib.sha256(text.encode()).hexdigest()


def _describe(type_name: str, fields: Fields) -> dict[str, Any]:
    return {"type_name": type_name,
            "fields": [{"name": name, "type": ftype} for name, ftype in fields]}
