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
        first = self.message_count == 0
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
    ROS 1 bag, a text file) or cut before its header ended; OSError if it cannot be read.
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
        loose = _inner(result, opcode, content, len(content))
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
    staged = Scan(result.path, result.size, channels=dict(result.channels))  # kept once whole
    while position < len(data):
        opcode, inner_length = _RECORD.unpack_from(data, position)
        body = data[position + _RECORD.size:position + _RECORD.size + inner_length]
        if len(body) != inner_length:
            raise ValueError("a record inside it runs past its end")
        message = _inner(staged, opcode, body, inner_length)
        if message is not None:
            index.setdefault(message.channel_id, []).append((message.log_time, position))
        position += _RECORD.size + inner_length
    result.schemas.update(staged.schemas)
    result.channels.update(staged.channels)
    for channel_id, entries in index.items():
        result.count(channel_id, min(time for time, _ in entries), len(entries))
        result.end_time = max(result.end_time, max(time for time, _ in entries))
    chunk.data = b""
    return ScannedChunk(offset, length, chunk, index, index_end=offset + length)


def _inner(result: Scan, opcode: int, body: bytes, length: int) -> Message | None:
    """A schema, channel or message record (in a chunk or not); the message, if one."""
    data = ReadDataStream(io.BytesIO(body))
    if opcode == Opcode.SCHEMA:
        schema = Schema.read(data)
        result.schemas[schema.id] = schema
    elif opcode == Opcode.CHANNEL:
        channel = Channel.read(data)
        result.channels[channel.id] = channel
    elif opcode == Opcode.MESSAGE:
        message: Message = Message.read(data, length)
        if message.channel_id not in result.channels:
            raise ValueError(f"a message on channel {message.channel_id}, never defined")
        result.count(message.channel_id, message.log_time)
        return message
    return None
