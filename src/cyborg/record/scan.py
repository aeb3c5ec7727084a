"""Reading an MCAP file record by record, from its start up to wherever it was cut.

A recorder killed with ``kill -9``, or a machine losing power, leaves a file with no summary
and maybe a record cut short at its end (or, after power loss, zeros where the file system
had not written yet). :func:`scan` reads the data section as the MCAP specification lays it
out — magic, header, then records of ``opcode (1 byte), length (8 bytes, little endian),
content`` — and keeps everything up to the last record that is whole: each chunk is
decompressed and its CRC checked, its schemas, channels and messages parsed; a chunk that is
cut, does not decompress or fails its CRC ends the scan, as does a record whose opcode or
length cannot be right. Nothing after that point is guessed at.

What it finds (:class:`Scan`) is what :mod:`cyborg.record.completion` needs to write the
indexes and summary the file lacks: the schemas and channels, each complete chunk with its
place and a message index rebuilt from its content, the metadata and attachment records, the
counts and times of the statistics, and where the whole part ends.

**Bounds.** Every reader of a recording does some work for each channel and schema, so a file
defining more than :data:`MAX_CHANNELS` channels or :data:`MAX_SCHEMAS` schemas, more channels
than one per :data:`BYTES_PER_CHANNEL` bytes of the file, or more than
:data:`MAX_DEFINITION_BYTES` of schema and channel records, is refused
(:class:`NotRecoverableError` naming the file and the byte where the record lies), not kept up
to that point. The scan's own work is linear in the records read.
"""

from __future__ import annotations

import io
import struct
import zlib
from dataclasses import dataclass, field
from pathlib import Path
from typing import BinaryIO

import lz4.frame
import zstandard
from mcap.data_stream import ReadDataStream
from mcap.opcode import Opcode
from mcap.records import (
    Attachment,
    AttachmentIndex,
    Channel,
    Chunk,
    Header,
    Message,
    MessageIndex,
    Metadata,
    MetadataIndex,
    Schema,
)

MAGIC = b"\x89MCAP0\r\n"
"""The 8 bytes an MCAP file starts (and ends) with."""
_RECORD = struct.Struct("<BQ")
_DATA_SECTION = {int(op) for op in (Opcode.HEADER, Opcode.SCHEMA, Opcode.CHANNEL,
                                    Opcode.MESSAGE, Opcode.CHUNK, Opcode.MESSAGE_INDEX,
                                    Opcode.ATTACHMENT, Opcode.METADATA, Opcode.DATA_END)}


MAX_CHANNELS = 10_000
"""Most channels a file may define (ROS systems have hundreds of topics)."""
MAX_SCHEMAS = 10_000
"""Most schemas a file may define."""
BYTES_PER_CHANNEL = 16
"""A file may define one channel per so many of its bytes: a channel record alone takes 25 or
more, and the summary of a finished file repeats it uncompressed."""
MAX_DEFINITION_BYTES = 64 * 2**20
"""Most bytes of schema and channel records a file may define (they are all kept in memory)."""


class NotRecoverableError(ValueError):
    """A file that is no MCAP recording, or one cut before anything could be kept."""


@dataclass
class ScannedChunk:
    """A complete chunk: where it lies, what it covers, and its messages' index."""

    offset: int
    length: int
    """Bytes of the whole chunk record, opcode and length included."""
    record: Chunk
    """The chunk record, its compressed data dropped once scanned."""
    message_index: dict[int, list[tuple[int, int]]]
    """(log time, offset in the uncompressed chunk) of each message, by channel id."""
    index_offsets: dict[int, int] = field(default_factory=dict)
    """Where the file already holds this chunk's message index records, by channel id."""
    index_end: int = 0
    """Where the message index records that follow it end (its end when none follow)."""

    @property
    def indexed(self) -> bool:
        """Whether the file holds a message index record for every channel of the chunk."""
        return set(self.index_offsets) == set(self.message_index)


@dataclass
class Scan:
    """What a scan of a file kept; see the module."""

    path: Path
    size: int
    header: Header | None = None
    schemas: dict[int, Schema] = field(default_factory=dict)
    channels: dict[int, Channel] = field(default_factory=dict)
    chunks: list[ScannedChunk] = field(default_factory=list)
    metadata: list[MetadataIndex] = field(default_factory=list)
    """Where each metadata record is, and its name."""
    attachments: list[AttachmentIndex] = field(default_factory=list)
    """Where each attachment is, and what it holds."""
    message_counts: dict[int, int] = field(default_factory=dict)
    loose: list[tuple[int, int, int]] = field(default_factory=list)
    """(log time, offset, channel id) of each message outside a chunk (an unchunked file)."""
    start_time: int = 0
    end_time: int = 0
    end: int = 0
    """Where the last whole record of the data section ends."""
    defined_bytes: int = 0
    """Bytes of the schema and channel records kept (see :data:`MAX_DEFINITION_BYTES`)."""
    defined_ids: dict[str, int] = field(default_factory=lambda: {"schema": 0, "channel": 0})
    """Schema and channel ids defined so far (a chunk's staged scan counts on from the
    file's)."""
    counted_any: bool = False
    """Whether a message was counted yet (:attr:`start_time` is then the first one's)."""
    finished: bool = False
    """Whether the data section ended properly (a Data End record was reached)."""
    stopped: str = ""
    """Why the scan stopped before a Data End record, e.g. "a chunk cut short at byte 9000"."""

    @property
    def message_count(self) -> int:
        """Messages kept, on every channel."""
        return sum(self.message_counts.values())

    def count(self, channel_id: int, log_time: int, messages: int = 1) -> None:
        """Counts ``messages`` on ``channel_id`` into the statistics, the first at ``log_time``."""
        first = not self.counted_any
        self.counted_any = True
        self.message_counts[channel_id] = self.message_counts.get(channel_id, 0) + messages
        self.start_time = log_time if first else min(self.start_time, log_time)
        self.end_time = max(self.end_time, log_time)


def identify(path: Path, start: bytes) -> str:
    """Why a file that does not start with the MCAP magic is not a recording, in words."""
    if not start:
        return f"{path}: the file is empty"
    if start.startswith(b"#ROSBAG V"):
        return f"{path}: a ROS 1 bag (rosbag v2), not an MCAP file"
    if start.startswith(b"SQLite format 3"):
        return f"{path}: an SQLite database (a rosbag2 .db3 file?), not an MCAP file"
    if len(start) < len(MAGIC) and MAGIC.startswith(start):
        return f"{path}: cut within its first {len(MAGIC)} bytes; nothing to recover"
    text = ""
    for cut in range(4):  # the sample may end inside a character: judge the whole ones
        try:
            text = start[:len(start) - cut].decode("utf-8")
            break
        except UnicodeDecodeError:
            continue
    printable = all(char.isprintable() or char in "\t\r\n" for char in text)
    kind = "a text file" if text and printable else "not an MCAP file"
    return f"{path}: {kind} (it does not start with the MCAP magic bytes)"


def scan(path: Path) -> Scan:
    """Reads ``path`` up to its last whole record; see the module.

    Raises :class:`NotRecoverableError` naming the file for one that is empty, foreign (a
    ROS 1 bag, a text file), cut before its header ended or past a bound of the module's;
    OSError if it cannot be read.
    """
    with open(path, "rb") as stream:
        size = stream.seek(0, io.SEEK_END)
        stream.seek(0)
        start = stream.read(len(MAGIC))
        if start != MAGIC:
            raise NotRecoverableError(identify(path, start + stream.read(64)))
        result = Scan(path, size, end=len(MAGIC))
        _read_records(stream, result)
    if result.header is None:
        raise NotRecoverableError(f"{path}: cut before the end of its header; nothing to "
                                  "recover")
    return result


def _read_records(stream: BinaryIO, result: Scan) -> None:
    offset = result.end
    while True:
        head = stream.read(_RECORD.size)
        if len(head) < _RECORD.size:
            result.stopped = (f"a record cut short at byte {offset}" if head else
                              f"the file ends at byte {offset} without its summary")
            return
        opcode, length = _RECORD.unpack(head)
        where = f"at byte {offset}"
        if opcode not in _DATA_SECTION or (result.header is None) != (opcode == Opcode.HEADER):
            result.stopped = f"no valid record {where} (opcode 0x{opcode:02x})"
            return
        if length > result.size - offset - _RECORD.size:
            result.stopped = f"a record cut short {where} ({Opcode(opcode).name.lower()})"
            return
        content = stream.read(length)
        try:
            kept = _keep(result, opcode, content, offset, _RECORD.size + length)
        except NotRecoverableError:
            raise
        except Exception as exc:  # bad content is where the good part ends
            result.stopped = (f"a damaged {Opcode(opcode).name.lower()} record {where}: "
                              f"{type(exc).__name__}: {exc}")
            return
        if not kept:
            result.finished = True
            return
        offset += _RECORD.size + length
        result.end = offset


def _keep(result: Scan, opcode: int, content: bytes, offset: int, length: int) -> bool:
    """Takes one whole record into ``result``; False at the Data End record."""
    data = ReadDataStream(io.BytesIO(content))
    if opcode == Opcode.HEADER:
        result.header = Header.read(data)
    elif opcode == Opcode.DATA_END:
        return False
    elif opcode == Opcode.CHUNK:
        result.chunks.append(_chunk(result, Chunk.read(data), offset, length))
    elif opcode == Opcode.MESSAGE_INDEX:
        index = MessageIndex.read(data)
        last = result.chunks[-1] if result.chunks else None
        if last is not None and last.index_end == offset:
            last.index_offsets[index.channel_id] = offset
            last.index_end = offset + length
    else:
        loose = _inner(result, opcode, content, len(content), f"at byte {offset}")
        if loose is not None:
            result.loose.append((loose.log_time, offset, loose.channel_id))
        if opcode == Opcode.METADATA:
            result.metadata.append(MetadataIndex(offset=offset, length=length,
                                                 name=Metadata.read(data).name))
        elif opcode == Opcode.ATTACHMENT:
            item = Attachment.read(data)
            result.attachments.append(AttachmentIndex(
                offset=offset, length=length, create_time=item.create_time,
                log_time=item.log_time, data_size=len(item.data), name=item.name,
                media_type=item.media_type))
    return True


MAX_CHUNK_BYTES = 256 * 1024 * 1024
"""Most bytes a chunk may declare uncompressed: ours close at 1 MiB of messages (one camera
frame may be larger), and the declared size was trusted: 98 KB of zstd declared 3 GiB."""


def decompress(chunk: Chunk) -> bytes:
    """A chunk's records, decompressed and checked; ValueError for a damaged chunk.

    A chunk declaring more than :data:`MAX_CHUNK_BYTES` uncompressed is refused before any
    decompression, and none is decompressed past what it declares.
    """
    if chunk.uncompressed_size > MAX_CHUNK_BYTES:
        raise ValueError(f"it declares {chunk.uncompressed_size:,} bytes uncompressed, more than "
                         f"the {MAX_CHUNK_BYTES // 2**20} MiB a chunk may hold")
    if chunk.compression == "zstd":  # a frame's own content size is not trusted either
        parts, wanted = [], chunk.uncompressed_size + 1
        with zstandard.ZstdDecompressor().stream_reader(chunk.data) as reader:
            while wanted > 0 and (part := reader.read(wanted)):
                parts.append(part)
                wanted -= len(part)
        data = b"".join(parts)
    elif chunk.compression == "lz4":
        data = lz4.frame.LZ4FrameDecompressor().decompress(
            chunk.data, max_length=chunk.uncompressed_size)
    elif chunk.compression == "":
        data = chunk.data
    else:
        raise ValueError(f"unknown compression {chunk.compression!r}")
    if len(data) != chunk.uncompressed_size:
        raise ValueError(f"{len(data)} bytes uncompressed, {chunk.uncompressed_size} expected")
    if chunk.uncompressed_crc and zlib.crc32(data) != chunk.uncompressed_crc:
        raise ValueError("the CRC of its content does not match")
    return bytes(data)


def _chunk(result: Scan, chunk: Chunk, offset: int, length: int) -> ScannedChunk:
    data = decompress(chunk)
    index: dict[int, list[tuple[int, int]]] = {}
    position = 0
    # what the chunk defines is kept once it is whole; only its own records are copied
    staged = Scan(result.path, result.size, defined_bytes=result.defined_bytes,
                  defined_ids=dict(result.defined_ids))
    where = f"in the chunk at byte {offset}"
    while position < len(data):
        opcode, inner_length = _RECORD.unpack_from(data, position)
        body = data[position + _RECORD.size:position + _RECORD.size + inner_length]
        if len(body) != inner_length:
            raise ValueError("a record inside it runs past its end")
        message = _inner(staged, opcode, body, inner_length, where, result)
        if message is not None:
            index.setdefault(message.channel_id, []).append((message.log_time, position))
        position += _RECORD.size + inner_length
    result.schemas.update(staged.schemas)
    result.channels.update(staged.channels)
    result.defined_bytes, result.defined_ids = staged.defined_bytes, staged.defined_ids
    for channel_id, entries in index.items():
        times = [time for time, _ in entries]
        result.count(channel_id, min(times), len(entries))
        result.end_time = max(result.end_time, max(times))
    chunk.data = b""
    return ScannedChunk(offset, length, chunk, index, index_end=offset + length)


def _inner(result: Scan, opcode: int, body: bytes, length: int, where: str,
           known: Scan | None = None) -> Message | None:
    """A schema, channel or message record (in a chunk or not); the message, if one.

    Schemas and channels go into ``result``; ``known`` holds those defined before, when
    ``result`` stages a chunk's own. ``where`` says where the record lies, for a refusal.
    """
    data = ReadDataStream(io.BytesIO(body))
    if opcode == Opcode.SCHEMA:
        schema = Schema.read(data)
        _admit(result, known, schema, where)
        result.schemas[schema.id] = schema
    elif opcode == Opcode.CHANNEL:
        channel = Channel.read(data)
        _admit(result, known, channel, where)
        result.channels[channel.id] = channel
    elif opcode == Opcode.MESSAGE:
        message: Message = Message.read(data, length)
        if message.channel_id not in result.channels and (
                known is None or message.channel_id not in known.channels):
            raise ValueError(f"a message on channel {message.channel_id}, never defined")
        result.count(message.channel_id, message.log_time)
        return message
    return None


def _size(record: Schema | Channel) -> int:
    """The bytes a schema or channel keeps in memory, near enough: its strings and data."""
    if isinstance(record, Schema):
        return len(record.data) + len(record.name) + len(record.encoding)
    return (len(record.topic) + len(record.message_encoding)
            + sum(len(key) + len(value) for key, value in record.metadata.items()))


def _admit(result: Scan, known: Scan | None, record: Schema | Channel, where: str) -> None:
    """Counts a schema or channel record about to be kept against the module's bounds.

    A record that defines an id again replaces the one before. Raises
    :class:`NotRecoverableError` naming the file and ``where`` the record lies when a new id
    passes :data:`MAX_SCHEMAS` or the channel bounds, or the records kept pass
    :data:`MAX_DEFINITION_BYTES`.
    """
    schema = isinstance(record, Schema)
    kind = "schema" if schema else "channel"
    replaced: Schema | Channel | None
    if schema:
        replaced = result.schemas.get(record.id) or (known.schemas.get(record.id)
                                                     if known is not None else None)
    else:
        replaced = result.channels.get(record.id) or (known.channels.get(record.id)
                                                      if known is not None else None)
    result.defined_bytes += _size(record) - (_size(replaced) if replaced is not None else 0)
    if result.defined_bytes > MAX_DEFINITION_BYTES:
        raise NotRecoverableError(
            f"{result.path}: more than {MAX_DEFINITION_BYTES:,} bytes of schema and channel "
            f"records (the {kind} record {where} passes it)")
    if replaced is not None:
        return
    count = result.defined_ids[kind] = result.defined_ids[kind] + 1
    most = MAX_SCHEMAS if schema else MAX_CHANNELS
    if count > most:
        raise NotRecoverableError(f"{result.path}: more than the {most:,} {kind}s a recording "
                                  f"may define ({kind} {record.id} {where} passes it)")
    if not schema and count > result.size // BYTES_PER_CHANNEL:
        raise NotRecoverableError(
            f"{result.path}: {count:,} channels in {result.size:,} bytes, more than one per "
            f"{BYTES_PER_CHANNEL} bytes of the file (channel {record.id} {where})")
