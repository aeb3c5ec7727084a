"""One MCAP file being recorded, in the rosbag2 layout, never more than a second behind.

:class:`McapFile` wraps the ``mcap`` library's writer: profile ``ros2``, one ``ros2msg``
schema per type, one ``cdr`` channel per topic (:mod:`cyborg.record.layout`), chunked (chunk
size :data:`CHUNK_SIZE`), compressed as asked, with chunk and message indexes, statistics and
summary offsets written at :meth:`McapFile.close`, with rosbag2's own ``rosbag2`` metadata
record (:mod:`cyborg.record.bag_metadata`) describing the file's topics, counts and times.

**Bounded loss.** The writer closes a chunk when it passes :data:`CHUNK_SIZE`; the recorder
also calls :meth:`McapFile.flush_if_due` often, which closes the open chunk once it is
:data:`FLUSH_INTERVAL` old and hands it to the operating system, then starts syncing the file
to disk (``fsync``, on the stream's own thread: :mod:`cyborg.record.guarded_stream`). So a
recorder killed with ``kill -9`` loses at most the last second or so, and a machine losing
power that plus what the disk had not yet taken; ``cyborg record --recover`` restores the rest
(:mod:`cyborg.record.recover`).

A message larger than :data:`CHUNK_SIZE` (a camera image) is a chunk of its own: larger
chunks were measured and do not help (docs/recording.md, "Images").

**Failed writes.** A write that fails (a full disk) stops the file
(:class:`~cyborg.record.guarded_stream.StorageError`); :meth:`McapFile.close` then finishes it
in place from a scan of what was written (:mod:`cyborg.record.completion`), dropping chunks
from its end only if even the summary finds no room, so the file stays readable and indexed.
"""

from __future__ import annotations

import errno
import logging
import os
import time
from pathlib import Path
from typing import BinaryIO

from mcap.writer import CompressionType, IndexType, Writer

from cyborg.bus import MessageTypes
from cyborg.record import bag_metadata, layout
from cyborg.record.bag_metadata import FileSummary, TopicCount
from cyborg.record.completion import complete, keep_until
from cyborg.record.guarded_stream import GuardedStream, StorageError
from cyborg.record.scan import NotRecoverableError, scan

log = logging.getLogger(__name__)

CHUNK_SIZE = 1024 * 1024
"""Bytes of messages after which a chunk is closed (compressed and written), as rosbag2's."""
FLUSH_INTERVAL = 1.0
"""Seconds after which an open chunk is closed, written and its sync started, however small."""
COMPRESSIONS = {"none": CompressionType.NONE, "lz4": CompressionType.LZ4,
                "zstd": CompressionType.ZSTD}
"""The compressions a recording may use, by the name the command line gives."""


class McapFile:
    """An MCAP file in the rosbag2 layout, open for writing; see the module.

    ``path`` must not exist yet (FileExistsError). ``raw`` replaces the file's own stream (a
    test's, to make writes fail). ``compression`` is a key of :data:`COMPRESSIONS`.
    """

    def __init__(self, path: Path, types: MessageTypes, *, compression: str = "zstd",
                 library: str = layout.LIBRARY, raw: BinaryIO | None = None) -> None:
        if compression not in COMPRESSIONS:
            raise ValueError(f"compression {compression!r}: expected one of "
                             f"{', '.join(COMPRESSIONS)}")
        self.path, self.types = path, types
        self.stream = GuardedStream(path, raw)
        self._writer = Writer(self.stream, chunk_size=CHUNK_SIZE,  # type: ignore[arg-type]
                              compression=COMPRESSIONS[compression],
                              index_types=IndexType.ALL)
        self._schemas: dict[str, int] = {}
        self._channels: dict[str, int] = {}
        self._chunk_opened: float | None = None
        self._written = self._pending = 0  # bytes in the file; bytes added since it grew
        self.messages = 0
        self.closed = False
        self.summary = FileSummary(path.name)
        """Its topics, counts and time span, written as the ``rosbag2`` record at close."""
        self.custom_data: dict[str, str] = {}
        """The run's metadata (the ``cyborg`` record), the rosbag2 record's ``custom_data``."""
        self._counted: dict[int, TopicCount] = {}
        self._writer.start(profile=layout.PROFILE, library=library)

    @property
    def size(self) -> int:
        """Bytes in the file so far, counting the open chunk's messages uncompressed."""
        self._note_growth()
        return self._written + self._pending

    def _note_growth(self) -> None:
        """Once the file has grown (a chunk went out), the open chunk starts from nothing."""
        if self.stream.good != self._written:
            self._written, self._pending = self.stream.good, 0

    @property
    def failed(self) -> StorageError | None:
        """The failed write that stopped this file, if one did."""
        return self.stream.failed

    def channel(self, topic: str, type_name: str, offered_qos: list[str]) -> int:
        """The channel id of ``topic``, registering it (and its type's schema) the first time."""
        if topic in self._channels:
            return self._channels[topic]
        schema = self._schemas.get(type_name)
        if schema is None:
            schema = self._writer.register_schema(
                type_name, layout.SCHEMA_ENCODING, layout.schema_text(self.types, type_name))
            self._schemas[type_name] = schema
        metadata = layout.channel_metadata(self.types, type_name, offered_qos)
        channel: int = self._writer.register_channel(
            topic, layout.MESSAGE_ENCODING, schema, metadata)
        self._channels[topic] = channel
        counted = TopicCount(topic, type_name, metadata[layout.QOS_KEY],
                             metadata[layout.TYPE_HASH_KEY])
        self._counted[channel] = self.summary.topics[topic] = counted
        return channel

    def channel_of(self, topic: str) -> int:
        """The channel id of a topic registered before; KeyError naming it otherwise."""
        try:
            return self._channels[topic]
        except KeyError:
            raise KeyError(f"{topic}: not a channel of {self.path}") from None

    def write(self, channel: int, log_time: int, publish_time: int, data: bytes) -> None:
        """Adds one message; raises StorageError once a write has failed."""
        if self._chunk_opened is None:
            self._chunk_opened = time.monotonic()
        self._note_growth()
        self._writer.add_message(channel, log_time, data, publish_time)
        self._pending += len(data) + 31  # the message record's own fields
        self.messages += 1
        self.summary.count(self._counted[channel], log_time)

    def metadata(self, name: str, values: dict[str, str]) -> None:
        """Adds a metadata record (indexed in the summary)."""
        self._writer.add_metadata(name, values)
        if name == layout.RUN_METADATA:
            self.custom_data = dict(values)

    def flush_if_due(self, now: float | None = None) -> bool:
        """Closes and writes the open chunk, and starts its sync, if it is old enough."""
        opened = self._chunk_opened
        now = time.monotonic() if now is None else now
        if opened is None or now - opened < FLUSH_INTERVAL:
            return False
        self.flush()
        return True

    def flush(self) -> None:
        """Closes and writes the open chunk now, and starts syncing it to the disk."""
        self._chunk_opened = None
        self._writer.flush()
        self.stream.sync()

    def close(self) -> None:
        """Finishes the file: summary and footer (in place, from a scan, after a failed write)."""
        if self.closed:
            return
        self.closed = True
        try:
            if self.failed is None:
                self._writer.add_metadata(bag_metadata.RECORD_NAME, {
                    bag_metadata.RECORD_KEY: bag_metadata.serialized([self.summary],
                                                                     self.custom_data)})
                self._writer.finish()
        except StorageError:
            pass
        finally:
            self.stream.close()
        if self.failed is not None:
            finish_in_place(self.path)


def finish_in_place(path: Path) -> bool:
    """Cuts a stopped file to its last whole record and appends its summary; True if indexed.

    When even the summary finds no room, the last chunk is dropped and it is tried again
    (each dropped chunk frees its bytes); failing that, the file is left cut at its last whole
    record: still readable in order, and ``--recover`` makes an indexed copy elsewhere.
    """
    try:
        found = scan(path)
    except (NotRecoverableError, OSError) as exc:
        log.error("%s: cannot be finished: %s", path, exc)
        return False
    while True:
        end = keep_until(found)
        try:
            with open(path, "r+b") as file:
                file.truncate(end)
                file.seek(end)
                complete(found, file, end)
                file.flush()
                os.fsync(file.fileno())
            return True
        except OSError as exc:
            if exc.errno not in (errno.ENOSPC, errno.EDQUOT) or not found.chunks:
                with open(path, "r+b") as file:
                    file.truncate(end)
                return False
            dropped = found.chunks.pop()
            found.end = dropped.offset
            found.metadata = [item for item in found.metadata if item.offset < dropped.offset]
            found.attachments = [item for item in found.attachments
                                 if item.offset < dropped.offset]
            for channel_id, entries in dropped.message_index.items():
                found.message_counts[channel_id] -= len(entries)
            found.end_time = max((chunk.record.message_end_time for chunk in found.chunks),
                                 default=0)
