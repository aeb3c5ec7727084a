"""ROS 1 and ROS 2 bags to play, read with rosbags' ``AnyReader``.

A ROS 2 bag (a folder with ``metadata.yaml`` holding ``.db3`` or ``.mcap`` files, or a ``.db3``
file in such a folder) holds CDR already: its messages are played as they are. Its topics are
latched when their offered QoS is transient-local.

A ROS 1 bag (``.bag``) holds ROS 1 serialisation. Each message is decoded with the bag's own
definitions and copied, field by field, into the bus's ROS 2 type of the same name, then
serialised as CDR: fields ROS 2 dropped (``std_msgs/Header``'s ``seq``) are left behind, a ROS
2 field the ROS 1 message lacks makes the topic unplayable (it is skipped and named, with the
field). Types the bus does not know are made known from the bag's definitions, taking the
bus's own for the types they use. Topics recorded from latching publishers are latched.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from rosbags.highlevel import AnyReader, AnyReaderError
from rosbags.interfaces import Connection, Nodetype, QosDurability
from rosbags.typesys import Stores, get_typestore

from cyborg.bus import MessageTypes
from cyborg.record.bag_checks import check_folder, check_ros1
from cyborg.record.recorded import (
    Played,
    PlayedTopic,
    Recording,
    RecordingError,
    TypeLearner,
    is_latched,
)

ROS1_MAGIC = b"#ROSBAG V2.0"
"""The first bytes of a ROS 1 bag."""


class ConversionError(ValueError):
    """A ROS 1 message that has no ROS 2 counterpart on the bus; names the field."""


class BagRecording(Recording):
    """A ROS 1 or ROS 2 bag; see the module."""

    _reader: AnyReader
    _connections: list[Connection]
    _ros1: bool
    _types: MessageTypes
    _learner: TypeLearner
    _why_type: dict[str, str | None]
    """Why each type's topics cannot play (None: they can), worked out once per type."""

    @classmethod
    def open(cls, path: Path, types: MessageTypes) -> BagRecording:
        """Opens the bag at ``path``; RecordingError naming it when it cannot be read."""
        bag = path
        if path.suffix == ".db3" and path.is_file():
            if not (path.parent / "metadata.yaml").is_file():
                raise RecordingError(f"{path}: a ROS 2 bag is a folder with metadata.yaml next "
                                     "to its storage files; none is here")
            bag = path.parent
        elif path.suffix == ".bag":
            with open(path, "rb") as stream:
                start = stream.read(len(ROS1_MAGIC))
            if start != ROS1_MAGIC:
                what = "empty" if not start else "not a ROS 1 bag (no #ROSBAG V2.0 header)"
                raise RecordingError(f"{path}: {what}")
            check_ros1(path)
        elif path.is_dir() and not (path / "metadata.yaml").is_file():
            raise RecordingError(f"{path}: a folder without metadata.yaml, neither an MCAP file "
                                 "nor a ROS 2 bag")
        if bag.is_dir():
            check_folder(bag)
        reader = AnyReader([bag], default_typestore=get_typestore(Stores.ROS2_HUMBLE))
        try:
            reader.open()
        except (AnyReaderError, OSError, ValueError, RecursionError) as exc:
            said = " ".join(str(exc).split()) or type(exc).__name__  # rosbags' run over lines
            raise RecordingError(f"{path}: cannot be read as a bag ({said})") from None
        recording = cls(path, start_ns=reader.start_time, end_ns=reader.end_time)
        recording._reader, recording._ros1, recording._types = reader, not reader.is2, types
        recording._learner, recording._why_type = TypeLearner(types), {}
        recording._connections = []
        for connection in reader.connections:
            why = recording._why_not(connection)
            if why is not None:
                recording.skip(PlayedTopic(connection.topic, connection.msgtype,
                                           _latched(connection), connection.msgcount), why)
                continue
            recording._connections.append(connection)
            known = recording.topics.get(connection.topic)
            count = connection.msgcount + (known.count if known else 0)
            recording.topics[connection.topic] = PlayedTopic(
                connection.topic, connection.msgtype, _latched(connection), count)
        if reader.message_count == 0:
            reader.close()
            raise RecordingError(f"{path}: holds no messages")
        return recording

    def _why_not(self, connection: Connection) -> str | None:
        """Why ``connection`` cannot play (None when it can)."""
        type_name = connection.msgtype
        known = self.topics.get(connection.topic)
        if known is not None and known.type_name != type_name:
            return f"recorded with two types, {known.type_name} and {type_name}"
        if type_name not in self._why_type:
            self._why_type[type_name] = self._why_not_type(type_name)
        return self._why_type[type_name]

    def _why_not_type(self, type_name: str) -> str | None:
        """Why topics of ``type_name`` cannot play (None when they can)."""
        if type_name not in self._types:
            try:
                definition, _ = self._reader.typestore.generate_msgdef(type_name, ros_version=2)
            except Exception as exc:  # rosbags' own errors for a type it cannot write out
                return f"unknown type {type_name} ({exc})"
            why = self._learner.learn(type_name, definition)
            if why is not None:
                return why
        if self._ros1:
            try:
                empty = _default(self._reader.typestore, type_name)
                _convert(self._types, empty, type_name, "")
            except ConversionError as exc:
                return f"its ROS 1 type {type_name} has no ROS 2 counterpart ({exc})"
        return None

    def _play(self, connection: Connection, raw: bytes) -> bytes:
        if not self._ros1:
            return bytes(raw)
        message = self._reader.typestore.deserialize_ros1(raw, connection.msgtype)
        converted = _convert(self._types, message, connection.msgtype, "")
        return bytes(self._types.serialize(converted, connection.msgtype))

    def messages(self, start_ns: int = 0) -> Iterator[Played]:
        """The played topics' messages from ``start_ns`` on, in time order."""
        for connection, log_time, raw in self._reader.messages(connections=self._connections,
                                                               start=start_ns):
            yield Played(connection.topic, log_time, self._play(connection, raw))

    def latched_before(self, start_ns: int) -> list[Played]:
        """The last message before ``start_ns`` of each latched topic (read from the start)."""
        latched = [c for c in self._connections if self.topics[c.topic].latched]
        if not latched or start_ns <= self.start_ns:
            return []
        last: dict[str, tuple[Connection, int, bytes]] = {}
        for connection, log_time, raw in self._reader.messages(connections=latched,
                                                               stop=start_ns):
            last[connection.topic] = (connection, log_time, raw)
        return sorted((Played(topic, log_time, self._play(connection, raw))
                       for topic, (connection, log_time, raw) in last.items()),
                      key=lambda played: played.log_time)

    def close(self) -> None:
        """Closes the bag."""
        if self._reader.stack is not None:
            self._reader.close()


def _latched(connection: Connection) -> bool:
    ext: Any = connection.ext
    if hasattr(ext, "latching"):
        return bool(ext.latching)
    profiles = getattr(ext, "offered_qos_profiles", None)
    if isinstance(profiles, str):
        return is_latched(profiles)
    return any(getattr(qos, "durability", None) == QosDurability.TRANSIENT_LOCAL
               for qos in profiles or ())


def _default(store: Any, type_name: str) -> Any:
    """A message of ``type_name`` with every field at its zero value (from ``store``)."""
    fields: Any = store.fielddefs[type_name][1]
    values: dict[str, Any] = {}
    for name, (kind, spec) in fields:
        if kind == Nodetype.NAME:
            values[name] = _default(store, spec)
        elif kind == Nodetype.BASE:
            values[name] = "" if spec[0] == "string" else False if spec[0] == "bool" else 0
        else:
            values[name] = []
    return store.types[type_name](**values)


def _convert(types: MessageTypes, message: Any, type_name: str, path: str) -> Any:
    """``message`` (a ROS 1 decoding) as the bus's ``type_name``, copied field by field."""
    fields: Any = types.store.fielddefs[type_name][1]  # (name, (kind, spec)) each
    values: dict[str, Any] = {}
    for name, (kind, spec) in fields:
        where = f"{path}{name}"
        if not hasattr(message, name):
            raise ConversionError(f"no field {where}")
        value = getattr(message, name)
        if kind == Nodetype.NAME:
            values[name] = _convert(types, value, spec, where + ".")
        elif kind in (Nodetype.ARRAY, Nodetype.SEQUENCE) and spec[0][0] == Nodetype.NAME:
            values[name] = [_convert(types, item, spec[0][1], f"{where}[].") for item in value]
        else:
            values[name] = value
    if dataclasses.is_dataclass(message) is False:
        raise ConversionError(f"{path or type_name}: not a message")
    return types.message_class(type_name)(**values)
