"""Recordings to play: their topics, and their messages in time order as CDR bytes.

:func:`open_recording` opens what ``cyborg play`` is given and returns a :class:`Recording`:

* an MCAP file (``cyborg record``'s, ``ros2 bag``'s, anyone's with ``cdr`` messages and
  ``ros2msg`` schemas) is read here, through :func:`cyborg.record.scan.scan`, so a file cut by
  ``kill -9`` or a power loss plays up to its last whole chunk (:attr:`Recording.cut` says
  where it was cut);
* a ROS 1 bag (``.bag``) or a ROS 2 bag (a folder with ``metadata.yaml``, or a ``.db3`` file in
  one) is read with rosbags' ``AnyReader`` (:mod:`cyborg.record.bag_recording`).

Every message comes as a :class:`Played`: topic, log time (ns) and the CDR bytes, encapsulation
header included, exactly as recorded (ROS 1 messages are converted, see the bag module). A
topic whose type the bus does not know is made known from the recording's own definition
(:meth:`cyborg.bus.MessageTypes.add_definition`); a topic that still cannot be played (another
message encoding, a definition that does not parse) is left out and named in
:attr:`Recording.skipped` with the reason. A file that is no recording (empty, a text file, a
ROS 1 bag or an SQLite file named ``.mcap``) raises :class:`RecordingError` naming the file and
what it is.
"""

from __future__ import annotations

import heapq
import io
import struct
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import BinaryIO, NamedTuple

from mcap.data_stream import ReadDataStream
from mcap.opcode import Opcode
from mcap.records import Channel, Chunk, Message, Schema

from cyborg.bus import MessageTypes
from cyborg.record import layout
from cyborg.record.scan import NotRecoverableError, ScannedChunk, decompress, scan

_RECORD = struct.Struct("<BQ")


class RecordingError(ValueError):
    """A file that cannot be played; the message names the file and what is wrong."""


class Played(NamedTuple):
    """One recorded message: its topic, its log time and its CDR bytes."""

    topic: str
    log_time: int
    """When it was recorded, ns (since the epoch for cyborg's recordings)."""
    data: bytes
    """CDR with its encapsulation header, as on the wire."""


@dataclass(frozen=True)
class PlayedTopic:
    """A topic of a recording that can be played."""

    name: str
    type_name: str
    latched: bool
    """Recorded from a transient-local publisher: played latched again."""
    count: int
    """Messages of it in the recording (what could be read of a cut file)."""


@dataclass
class Recording:
    """A recording opened for play; read its messages with :meth:`messages`.

    The base class holds what every kind of recording tells; :class:`McapRecording` and
    :class:`~cyborg.record.bag_recording.BagRecording` read them.
    """

    path: Path
    topics: dict[str, PlayedTopic] = field(default_factory=dict)
    skipped: dict[str, str] = field(default_factory=dict)
    """Topics that are not played, with the reason."""
    start_ns: int = 0
    """Log time of the first message."""
    end_ns: int = 0
    """Log time of the last message."""
    cut: str | None = None
    """Where and how the file was cut (only its whole part plays); None for a whole file."""

    @property
    def duration(self) -> float:
        """Seconds from the first message to the last."""
        return max(self.end_ns - self.start_ns, 0) / 1e9

    def messages(self, start_ns: int = 0) -> Iterator[Played]:
        """The messages of the played topics from ``start_ns`` on, in log-time order."""
        raise NotImplementedError

    def latched_before(self, start_ns: int) -> list[Played]:
        """The last message before ``start_ns`` of each latched topic, in log-time order."""
        raise NotImplementedError

    def close(self) -> None:
        """Releases the file."""


def open_recording(path: Path, types: MessageTypes) -> Recording:
    """Opens ``path`` to play it on a bus whose types are ``types``; see the module.

    Raises :class:`RecordingError` naming the file for one that cannot be played.
    """
    if not path.exists():
        raise RecordingError(f"{path}: no such file or folder")
    if path.is_dir() or path.suffix in (".bag", ".db3"):
        from cyborg.record.bag_recording import BagRecording
        return BagRecording.open(path, types)
    return McapRecording.open(path, types)


def learn_type(types: MessageTypes, type_name: str, definition: str) -> str | None:
    """Makes ``type_name`` known to the bus from a recording's definition text, if needed.

    Returns None when the bus knows it (now), else why it cannot be played.
    """
    if type_name in types:
        return None
    if not definition.strip():
        return f"unknown type {type_name}, and the recording holds no definition of it"
    try:
        types.add_definition(type_name, definition)
    except ValueError as exc:
        return str(exc)
    return None if type_name in types else f"unknown type {type_name}"


def is_latched(qos_yaml: str) -> bool:
    """Whether the ``offered_qos_profiles`` of a rosbag2 channel name a transient-local one."""
    return "transient_local" in qos_yaml


class McapRecording(Recording):
    """An MCAP file in the rosbag2 layout, whole or cut; see the module."""

    _stream: BinaryIO
    _chunks: list[ScannedChunk]
    _channels: dict[int, str]
    """The topic of each played channel, by channel id."""

    @classmethod
    def open(cls, path: Path, types: MessageTypes) -> McapRecording:
        """Scans ``path`` and learns its types; RecordingError if it is no MCAP recording."""
        try:
            found = scan(path)
        except NotRecoverableError as exc:
            raise RecordingError(str(exc).replace("; nothing to recover", "")) from None
        except OSError as exc:
            raise RecordingError(f"{path}: cannot be read ({exc.strerror or exc})") from None
        recording = cls(path, start_ns=found.start_time, end_ns=found.end_time)
        if not found.finished:
            recording.cut = found.stopped
        if found.message_count == 0:
            raise RecordingError(f"{path}: holds no messages"
                                 + (f" (cut: {found.stopped})" if not found.finished else ""))
        recording._chunks = sorted(found.chunks, key=lambda c: c.record.message_start_time)
        recording._channels = {}
        for channel_id, channel in sorted(found.channels.items()):
            why = recording._why_not(types, channel, found.schemas)
            count = found.message_counts.get(channel_id, 0)
            if why is not None:
                recording.skipped[channel.topic] = why
                continue
            schema = found.schemas[channel.schema_id]
            recording._channels[channel_id] = channel.topic
            recording.topics[channel.topic] = PlayedTopic(
                channel.topic, schema.name, is_latched(channel.metadata.get(layout.QOS_KEY, "")),
                count)
        recording._stream = open(path, "rb")  # noqa: SIM115 (closed by close())
        return recording

    @staticmethod
    def _why_not(types: MessageTypes, channel: Channel, schemas: dict[int, Schema]
                 ) -> str | None:
        if channel.message_encoding != layout.MESSAGE_ENCODING:
            return f"message encoding {channel.message_encoding!r}, not cdr"
        schema = schemas.get(channel.schema_id)
        if schema is None:
            return "no schema"
        if schema.encoding != layout.SCHEMA_ENCODING and schema.name not in types:
            return (f"unknown type {schema.name} with a {schema.encoding or 'missing'} schema, "
                    "not ros2msg")
        return learn_type(types, schema.name, schema.data.decode("utf-8", errors="replace"))

    def _records(self, chunk: ScannedChunk) -> bytes:
        """The decompressed content of a chunk (its messages' records)."""
        self._stream.seek(chunk.offset + _RECORD.size)
        content = self._stream.read(chunk.length - _RECORD.size)
        return decompress(Chunk.read(ReadDataStream(io.BytesIO(content))))

    def _messages_of(self, chunk: ScannedChunk, start_ns: int) -> Iterator[Played]:
        data = self._records(chunk)
        position = 0
        while position < len(data):
            opcode, length = _RECORD.unpack_from(data, position)
            body = position + _RECORD.size
            if opcode == Opcode.MESSAGE:
                message = Message.read(ReadDataStream(io.BytesIO(data[body:body + length])),
                                       length)
                topic = self._channels.get(message.channel_id)
                if topic is not None and message.log_time >= start_ns:
                    yield Played(topic, message.log_time, bytes(message.data))
            position = body + length

    def messages(self, start_ns: int = 0) -> Iterator[Played]:
        """The played topics' messages from ``start_ns`` on, merged across chunks in time."""
        pending: list[tuple[int, int, Played]] = []
        order = 0
        chunks = [c for c in self._chunks if c.record.message_end_time >= start_ns]
        for number, chunk in enumerate(chunks):
            for played in self._messages_of(chunk, start_ns):
                heapq.heappush(pending, (played.log_time, order, played))
                order += 1
            following = (chunks[number + 1].record.message_start_time
                         if number + 1 < len(chunks) else None)
            while pending and (following is None or pending[0][0] < following):
                yield heapq.heappop(pending)[2]

    def latched_before(self, start_ns: int) -> list[Played]:
        """The last message before ``start_ns`` of each latched topic (found by the index)."""
        found: list[Played] = []
        for channel_id, topic in self._channels.items():
            if not self.topics[topic].latched:
                continue
            last: tuple[int, ScannedChunk, int] | None = None
            for chunk in self._chunks:
                for log_time, offset in chunk.message_index.get(channel_id, []):
                    if log_time < start_ns and (last is None or log_time >= last[0]):
                        last = (log_time, chunk, offset)
            if last is not None:
                found.append(self._message_at(topic, last[1], last[2]))
        return sorted(found, key=lambda played: played.log_time)

    def _message_at(self, topic: str, chunk: ScannedChunk, offset: int) -> Played:
        data = self._records(chunk)
        _opcode, length = _RECORD.unpack_from(data, offset)
        body = offset + _RECORD.size
        message = Message.read(ReadDataStream(io.BytesIO(data[body:body + length])), length)
        return Played(topic, message.log_time, bytes(message.data))

    def close(self) -> None:
        """Closes the file."""
        self._stream.close()
