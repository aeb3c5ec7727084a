"""Reading a recording back with independent readers, and messages as plain values to compare.

``mcap`` with ``mcap-ros2-support`` decoding, and rosbags' ``AnyReader``: neither shares code
with cyborg's writer, and both build their decoders from the schema text in the file.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

import numpy as np
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
from rosbags.highlevel import AnyReader
from rosbags.typesys import Stores, get_typestore


def plain(value: Any) -> Any:
    """A message (any library's class) as dicts, lists and numbers; constants left out."""
    if isinstance(value, np.ndarray):
        return [plain(item) for item in value.tolist()]
    if isinstance(value, list | tuple):
        return [plain(item) for item in value]
    if isinstance(value, np.generic):
        return value.item()
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {field.name: plain(getattr(value, field.name))
                for field in dataclasses.fields(value) if not field.name.isupper()
                and field.name != "__msgtype__"}
    slots = getattr(type(value), "__slots__", None)
    if slots is not None and not isinstance(value, str | bytes | int | float):
        return {name: plain(getattr(value, name)) for name in slots}
    if isinstance(value, bytes):
        return list(value)
    return value


def read_mcap(path: Path) -> dict[str, list[Any]]:
    """Every message by topic, decoded by ``mcap_ros2``, in log-time order."""
    found: dict[str, list[Any]] = {}
    with open(path, "rb") as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        for _schema, channel, _message, decoded in reader.iter_decoded_messages(
                log_time_order=True):
            found.setdefault(channel.topic, []).append(plain(decoded))
    return found


def read_rosbags(path: Path) -> dict[str, list[Any]]:
    """Every message by topic, decoded by rosbags' AnyReader from the file's own schemas."""
    found: dict[str, list[Any]] = {}
    with AnyReader([path], default_typestore=get_typestore(Stores.EMPTY)) as reader:
        for connection, _time, raw in reader.messages():
            decoded = reader.deserialize(raw, connection.msgtype)
            found.setdefault(connection.topic, []).append(plain(decoded))
    return found


def raw_messages(path: Path) -> list[tuple[str, int, int, bytes]]:
    """(topic, log time, publish time, data) of every message, in file order."""
    with open(path, "rb") as stream:
        reader = make_reader(stream)
        return [(channel.topic, message.log_time, message.publish_time, message.data)
                for _schema, channel, message in reader.iter_messages(log_time_order=False)]
