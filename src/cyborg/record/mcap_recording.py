"""MCAP files to play, whole or cut, read through the scan of ``cyborg record --recover``.

:class:`McapRecording` reads an MCAP file in the rosbag2 layout (cyborg's, ``ros2 bag``'s,
anyone's with ``cdr`` messages) with :func:`cyborg.record.scan.scan`: every whole chunk is
found and indexed, so a file cut by ``kill -9`` or a power loss plays up to its last whole
chunk (:attr:`~cyborg.record.recorded.Recording.cut` says where it was cut). Messages are read
chunk by chunk and merged across chunks in log-time order (with those of a file written
without chunks, read one by one where the scan found them); the latched topics' last messages
before a time are found through the chunks' message indexes. A channel whose encoding is not
``cdr``, or whose type cannot be made known from a ``ros2msg`` schema, is skipped and named.
Each schema is read once, however many channels use it, and within the bounds of
:class:`~cyborg.record.recorded.TypeLearner`.
"""

from __future__ import annotations

import heapq
import io
import os
import struct
from collections.abc import Iterator
from pathlib import Path
from typing import BinaryIO

from mcap.data_stream import ReadDataStream
from mcap.opcode import Opcode
from mcap.records import Chunk, Message, Metadata, MetadataIndex, Schema

from cyborg.bus import MessageTypes
from cyborg.record import layout
from cyborg.record.recorded import (
    Played,
    PlayedTopic,
    Recording,
    RecordingError,
    TypeLearner,
    is_latched,
)
from cyborg.record.scan import NotRecoverableError, ScannedChunk, decompress, scan

_RECORD = struct.Struct("<BQ")


class McapRecording(Recording):
    """An MCAP file in the rosbag2 layout, whole or cut; see the module."""

    _stream: BinaryIO
    _chunks: list[ScannedChunk]
    _loose: list[tuple[int, int, int]]
    """(log time, offset, channel id) of the messages outside chunks, in log-time order."""
    _channels: dict[int, str]
    """The topic of each played channel, by channel id."""

    @classmethod
    def open(cls, path: Path, types: MessageTypes) -> McapRecording:
        """Scans ``path`` and learns its types; RecordingError if it is no MCAP recording."""
        try:
            found = scan(path)
        except NotRecoverableError as exc:
            said = str(exc).replace("; nothing to recover", "")
            if "a ROS 1 bag" in said:
                said += "; rename it to .bag to read it as one"
            raise RecordingError(said) from None
        except OSError as exc:
            raise RecordingError(f"{path}: cannot be read ({exc.strerror or exc})") from None
        recording = cls(path, start_ns=found.start_time, end_ns=found.end_time)
        if not found.finished:
            recording.cut = found.stopped
        if found.message_count == 0:
            raise RecordingError(f"{path}: holds no messages"
                                 + (f" (cut: {found.stopped})" if not found.finished else ""))
        recording._chunks = sorted(found.chunks, key=lambda c: c.record.message_start_time)
        recording._loose = sorted(found.loose)
        recording._channels = {}
        learner = TypeLearner(types)
        learnt: dict[int, str | None] = {}  # why not, by schema id (None: its channels play)
        for channel_id, channel in sorted(found.channels.items()):
            schema = found.schemas.get(channel.schema_id)
            topic = PlayedTopic(channel.topic, schema.name if schema else "",
                                is_latched(channel.metadata.get(layout.QOS_KEY, "")),
                                found.message_counts.get(channel_id, 0))
            why: str | None
            if channel.message_encoding != layout.MESSAGE_ENCODING:
                why = f"message encoding {channel.message_encoding!r}, not cdr"
            else:
                if channel.schema_id not in learnt:
                    learnt[channel.schema_id] = recording._why_not(learner, channel.schema_id,
                                                                   found.schemas)
                why = learnt[channel.schema_id]
            if why is not None:
                recording.skip(topic, why)
                continue
            recording._channels[channel_id] = channel.topic
            recording.topics[channel.topic] = topic
        recording._stream = open(path, "rb")  # noqa: SIM115 (closed by close())
        recording.metadata = [recording._metadata_at(item) for item in found.metadata]
        return recording

    def _metadata_at(self, where: MetadataIndex) -> tuple[str, dict[str, str]]:
        """The metadata record the scan found at ``where`` (checked whole by the scan)."""
        content = os.pread(self._stream.fileno(), where.length - _RECORD.size,
                           where.offset + _RECORD.size)
        record = Metadata.read(ReadDataStream(io.BytesIO(content)))
        return record.name, dict(record.metadata)

    @staticmethod
    def _why_not(learner: TypeLearner, schema_id: int, schemas: dict[int, Schema]
                 ) -> str | None:
        """Why the channels of schema ``schema_id`` cannot play (None when they can)."""
        schema = schemas.get(schema_id)
        if schema is None:
            return f"no schema (schema id {schema_id}), so its type is not known"
        if not schema.name:
            return "a schema without a type name"
        if schema.encoding != layout.SCHEMA_ENCODING and schema.name not in learner.types:
            return (f"unknown type {schema.name} with a {schema.encoding or 'missing'} schema, "
                    "not ros2msg")
        return learner.learn(schema.name, schema.data.decode("utf-8", errors="replace"))

    def _records(self, chunk: ScannedChunk) -> bytes:
        """The decompressed content of a chunk (its messages' records)."""
        # pread: no shared file position, so two readers (a seek, a test) never mix
        content = os.pread(self._stream.fileno(), chunk.length - _RECORD.size,
                           chunk.offset + _RECORD.size)
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
        """The played topics' messages from ``start_ns`` on, merged across chunks in time.

        Messages outside chunks (a file written unchunked) are merged in by their log time.
        """
        loose = (self._loose_at(offset) for log_time, offset, channel_id in self._loose
                 if log_time >= start_ns and channel_id in self._channels)
        return heapq.merge(self._chunked(start_ns), loose, key=lambda played: played.log_time)

    def _chunked(self, start_ns: int) -> Iterator[Played]:
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
            last: tuple[int, ScannedChunk | None, int] | None = None
            for chunk in self._chunks:
                for log_time, offset in chunk.message_index.get(channel_id, []):
                    if log_time < start_ns and (last is None or log_time >= last[0]):
                        last = (log_time, chunk, offset)
            for log_time, offset, loose_channel in self._loose:
                if (loose_channel == channel_id and log_time < start_ns
                        and (last is None or log_time >= last[0])):
                    last = (log_time, None, offset)
            if last is not None:
                found.append(self._loose_at(last[2]) if last[1] is None else
                             self._message_at(topic, last[1], last[2]))
        return sorted(found, key=lambda played: played.log_time)

    def _loose_at(self, offset: int) -> Played:
        """The message record at ``offset`` of the file, outside any chunk."""
        _opcode, length = _RECORD.unpack(os.pread(self._stream.fileno(), _RECORD.size, offset))
        body = os.pread(self._stream.fileno(), length, offset + _RECORD.size)
        message = Message.read(ReadDataStream(io.BytesIO(body)), length)
        return Played(self._channels[message.channel_id], message.log_time, bytes(message.data))

    def _message_at(self, topic: str, chunk: ScannedChunk, offset: int) -> Played:
        data = self._records(chunk)
        _opcode, length = _RECORD.unpack_from(data, offset)
        body = offset + _RECORD.size
        message = Message.read(ReadDataStream(io.BytesIO(data[body:body + length])), length)
        return Played(topic, message.log_time, bytes(message.data))

    def close(self) -> None:
        """Closes the file."""
        self._stream.close()
