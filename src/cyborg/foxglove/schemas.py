"""The schemas Foxglove is told for each channel: ROS 2 definitions, and JSON Schema for ours.

A ROS 2 topic's channel carries its type's full ``ros2msg`` definition, as rosbag2 writes it
into MCAP files: the type's own ``.msg`` text first, then each type it uses once, after a line
of 80 ``=`` and a line ``MSG: pkg/Type`` (rosbags writes it so, :func:`ros2msg_schema`).
Foxglove decodes the CDR payloads by it, with no package installed on the viewer's side.
"""

from __future__ import annotations

import json
from typing import Any

import foxglove

from cyborg.bus import MessageTypes

ROS2MSG = "ros2msg"
"""The schema encoding of ROS 2 message definitions (MCAP's ``ros2`` profile)."""
CDR = "cdr"
"""The message encoding of ROS 2 payloads: CDR with its 4-byte encapsulation header."""
JSON = "json"
"""The message encoding of the channels cyborg writes as JSON."""
JSON_SCHEMA = "jsonschema"
"""The schema encoding of JSON channels."""


def ros2msg_definition(types: MessageTypes, type_name: str) -> str:
    """The full definition text of ``type_name`` (``pkg/msg/Type``); KeyError if unknown."""
    if type_name not in types.store.fielddefs:
        raise KeyError(f"unknown message type {type_name!r}")
    text, _md5 = types.store.generate_msgdef(type_name, ros_version=2)
    return str(text)


def ros2msg_schema(types: MessageTypes, type_name: str) -> foxglove.Schema:
    """The Foxglove schema of a ROS 2 type: its name and full ``ros2msg`` definition."""
    return foxglove.Schema(name=type_name, encoding=ROS2MSG,
                           data=ros2msg_definition(types, type_name).encode("utf-8"))


def json_schema(name: str, schema: dict[str, Any]) -> foxglove.Schema:
    """A Foxglove schema for a JSON channel: ``name`` and a JSON Schema document."""
    return foxglove.Schema(name=name, encoding=JSON_SCHEMA,
                           data=json.dumps(schema).encode("utf-8"))
