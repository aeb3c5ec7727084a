"""Writing what a cut MCAP file lacks: its last chunk's message index, the summary, the footer.

Given a :class:`~cyborg.record.scan.Scan` of a file, :func:`complete` appends, at the end of
the part worth keeping (:func:`keep_until`), what the MCAP writer would have written at its
close: the message index records of the last chunk if they were cut, the Data End record,
the summary section (schemas, channels, statistics, chunk, attachment and metadata indexes),
the summary offsets, the footer (with the summary's CRC) and the closing magic. The result is
a file that readers open and seek at once, without the "unindexed" warning.

Used in two places: ``cyborg record --recover`` writes it after a copy of the kept part
(:mod:`cyborg.record.recover`), and a recording whose disk filled up finishes its own file
this way, in place (:mod:`cyborg.record.mcap_file`).
"""

from __future__ import annotations

import struct
import zlib
from typing import BinaryIO

from mcap.data_stream import RecordBuilder
from mcap.opcode import Opcode
from mcap.records import (
    ChunkIndex,
    DataEnd,
    Footer,
    MessageIndex,
    Statistics,
    SummaryOffset,
)

from cyborg.record.scan import MAGIC, Scan, ScannedChunk


def keep_until(scan: Scan) -> int:
    """Where the kept part of the scanned file ends.

    That is the end of its last whole record, except when the last chunk's message index
    records were cut short: then the end of that chunk, whose index is written anew.
    """
    last = scan.chunks[-1] if scan.chunks else None
    if last is not None and not last.indexed and last.index_end == scan.end:
        return last.offset + last.length
    return scan.end


def complete(scan: Scan, out: BinaryIO, position: int) -> int:
    """Appends the missing index, summary and footer to ``out``; returns the bytes written.

    ``out`` holds the kept part of the scanned file and stands at its end, ``position`` (which
    is :func:`keep_until`'s offset).
    """
    builder = RecordBuilder()
    chunk_indexes = []
    for chunk in scan.chunks:
        offsets, index_length = dict(chunk.index_offsets), chunk.index_end - _end(chunk)
        if not chunk.indexed:
            offsets, index_length = {}, 0
            if _end(chunk) == position:  # the last chunk: its index goes right after it
                for channel_id, entries in chunk.message_index.items():
                    offsets[channel_id] = position + builder.count
                    MessageIndex(channel_id, entries).write(builder)
                index_length = builder.count
        record = chunk.record
        chunk_indexes.append(ChunkIndex(
            message_start_time=record.message_start_time,
            message_end_time=record.message_end_time, chunk_start_offset=chunk.offset,
            chunk_length=chunk.length, message_index_offsets=offsets,
            message_index_length=index_length, compression=record.compression,
            compressed_size=chunk.length - _chunk_overhead(chunk),
            uncompressed_size=record.uncompressed_size))
    DataEnd(0).write(builder)
    summary_start = position + builder.count
    summary = RecordBuilder()
    groups: list[SummaryOffset] = []

    def group(opcode: Opcode, records: list[object]) -> None:
        start = summary.count
        for item in records:
            item.write(summary)  # type: ignore[attr-defined]
        if records:
            groups.append(SummaryOffset(group_opcode=opcode, group_start=summary_start + start,
                                        group_length=summary.count - start))

    group(Opcode.SCHEMA, list(scan.schemas.values()))
    group(Opcode.CHANNEL, list(scan.channels.values()))
    group(Opcode.STATISTICS, [_statistics(scan)])
    group(Opcode.CHUNK_INDEX, list(chunk_indexes))
    group(Opcode.ATTACHMENT_INDEX, list(scan.attachments))
    group(Opcode.METADATA_INDEX, list(scan.metadata))
    offsets_start = summary_start + summary.count
    for offset in groups:
        offset.write(summary)
    summary_data = summary.end()
    crc = zlib.crc32(summary_data)
    crc = zlib.crc32(struct.pack("<BQQQ", Opcode.FOOTER, 20, summary_start, offsets_start), crc)
    Footer(summary_start=summary_start, summary_offset_start=offsets_start,
           summary_crc=crc).write(summary)
    data = builder.end() + summary_data + summary.end() + MAGIC
    out.write(data)
    return len(data)


def _end(chunk: ScannedChunk) -> int:
    return chunk.offset + chunk.length


def _chunk_overhead(chunk: ScannedChunk) -> int:
    """Bytes of a chunk record that are not its compressed data."""
    # opcode, length; start, end, uncompressed size, CRC; compression string; data length
    return 1 + 8 + 8 + 8 + 8 + 4 + 4 + len(chunk.record.compression.encode()) + 8


def _statistics(scan: Scan) -> Statistics:
    return Statistics(
        message_count=scan.message_count, schema_count=len(scan.schemas),
        channel_count=len(scan.channels), attachment_count=len(scan.attachments),
        metadata_count=len(scan.metadata), chunk_count=len(scan.chunks),
        message_start_time=scan.start_time, message_end_time=scan.end_time,
        channel_message_counts=dict(scan.message_counts))
