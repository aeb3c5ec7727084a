"""A recording read back for a report: its topics, its metadata and the messages a report uses.

:func:`read_recording` first scans the file with :func:`cyborg.record.scan.scan`, which
refuses what is no recording (empty, a ROS 1 bag or a text file named ``.mcap``, a file cut
inside its header) with an error naming the file, and finds where the readable part ends: the
whole file, or, for a file cut by ``kill -9`` or a power loss, its last whole record. It then
reads that part in order with the ``mcap`` library's stream reader, so a cut file gives
everything it holds and the report says it was cut (:attr:`Recording.cut`).

Every message is counted; only those a report draws are decoded (``wanted(topic, type)``),
with the bus's own message types (:class:`cyborg.bus.MessageTypes`), from the CDR bytes as
they travelled. A topic whose type the bus does not know, or a message that does not decode,
is kept as a note in :attr:`Recording.problems`, never an error: the rest is still reported.
"""

from __future__ import annotations

import io
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from mcap.exceptions import McapError
from mcap.records import Channel, Message, Metadata, Schema
from mcap.stream_reader import StreamReader

from cyborg.bus import MessageTypes
from cyborg.record.scan import NotRecoverableError, scan

MAX_PROBLEMS_PER_TOPIC = 3
"""Decoding problems noted for one topic; the rest are only counted."""


class ReportInputError(ValueError):
    """A file a report cannot be made of; the message names the file and what is wrong."""


@dataclass(frozen=True)
class Stamped:
    """A decoded message and when the recorder received it (ns since the epoch)."""

    log_time: int
    message: Any


@dataclass
class TopicRecord:
    """One recorded topic: its type and how many of its messages the file holds."""

    name: str
    type_name: str
    count: int = 0


@dataclass
class Recording:
    """What a recording holds, as far as it could be read; see the module."""

    path: Path
    size: int
    metadata: list[tuple[str, dict[str, str]]] = field(default_factory=list)
    """Each metadata record's name and values, in file order."""
    topics: dict[str, TopicRecord] = field(default_factory=dict)
    messages: dict[str, list[Stamped]] = field(default_factory=dict)
    """The decoded messages of the topics asked for, by topic, in log-time order."""
    start: int = 0
    """Log time of the first message (ns); 0 when there is none."""
    end: int = 0
    cut: str = ""
    """Why the file ends before its summary (a cut file), or "" for a complete one."""
    problems: list[str] = field(default_factory=list)
    """Topics and messages that could not be decoded, said once each."""

    @property
    def message_count(self) -> int:
        """Messages in the readable part of the file, on every topic."""
        return sum(topic.count for topic in self.topics.values())

    @property
    def duration(self) -> float:
        """Seconds from the first message to the last."""
        return (self.end - self.start) / 1e9

    def metadata_named(self, name: str) -> list[dict[str, str]]:
        """The values of every metadata record called ``name``."""
        return [values for record, values in self.metadata if record == name]

    def stamped(self, topic: str) -> list[Stamped]:
        """The decoded messages of ``topic`` (none when it was not recorded or not asked for)."""
        return self.messages.get(topic, [])

    def seconds(self, log_time: int) -> float:
        """A log time as seconds since the recording's first message."""
        return (log_time - self.start) / 1e9


class _Prefix(io.RawIOBase):
    """The first ``end`` bytes of a file: the part a scan found whole."""

    def __init__(self, stream: io.BufferedReader, end: int) -> None:
        self._stream, self._left = stream, end

    def readable(self) -> bool:
        return True

    def readinto(self, buffer: Any) -> int:
        view = memoryview(buffer)[:self._left]
        count = self._stream.readinto(view)
        self._left -= count
        return count


def read_recording(path: Path, wanted: Callable[[str, str], bool],
                   types: MessageTypes | None = None) -> Recording:
    """Reads ``path``; see the module. ReportInputError names the file and what is wrong."""
    try:
        found = scan(path)
    except NotRecoverableError as exc:
        raise ReportInputError(str(exc)) from None
    except IsADirectoryError:
        raise ReportInputError(f"{path}: a folder, not an MCAP file") from None
    except FileNotFoundError:
        raise ReportInputError(f"{path}: no such file") from None
    except OSError as exc:
        raise ReportInputError(f"{path}: cannot be read: {exc.strerror or exc}") from None
    result = Recording(path, found.size, cut="" if found.finished else found.stopped)
    reader = _Reader(result, wanted, types or MessageTypes())
    with open(path, "rb") as stream:
        try:
            for record in StreamReader(_Prefix(stream, found.end)).records:
                reader.take(record)
        except (McapError, EOFError, ValueError, OSError):
            pass  # the end of the part a scan found whole
    for messages in result.messages.values():
        messages.sort(key=lambda stamped: stamped.log_time)
    return result


class _Reader:
    """Takes the records of a file, one at a time, into a :class:`Recording`."""

    def __init__(self, result: Recording, wanted: Callable[[str, str], bool],
                 types: MessageTypes) -> None:
        self.result, self.wanted, self.types = result, wanted, types
        self.schemas: dict[int, str] = {}
        self.channels: dict[int, tuple[TopicRecord, bool]] = {}
        self.failures: dict[str, int] = {}

    def take(self, record: Any) -> None:
        if isinstance(record, Message):
            self._message(record)
        elif isinstance(record, Schema):
            self.schemas[record.id] = record.name
        elif isinstance(record, Channel):
            self._channel(record)
        elif isinstance(record, Metadata):
            self.result.metadata.append((record.name, dict(record.metadata)))

    def _channel(self, channel: Channel) -> None:
        type_name = self.schemas.get(channel.schema_id, "")
        topic = self.result.topics.setdefault(channel.topic,
                                              TopicRecord(channel.topic, type_name))
        decode = self.wanted(channel.topic, type_name)
        if decode and type_name not in self.types:
            self.result.problems.append(f"{channel.topic}: its type {type_name or '(none)'} "
                                        "is not known here; not decoded")
            decode = False
        self.channels[channel.id] = (topic, decode)

    def _message(self, message: Message) -> None:
        known = self.channels.get(message.channel_id)
        if known is None:
            return
        topic, decode = known
        topic.count += 1
        result = self.result
        result.start = message.log_time if not result.start else min(result.start,
                                                                       message.log_time)
        result.end = max(result.end, message.log_time)
        if not decode:
            return
        try:
            decoded = self.types.deserialize(message.data, topic.type_name)
        except Exception as exc:  # a message the recording holds but our type cannot read
            failures = self.failures[topic.name] = self.failures.get(topic.name, 0) + 1
            if failures <= MAX_PROBLEMS_PER_TOPIC:
                result.problems.append(f"{topic.name}: a message at "
                                       f"{result.seconds(message.log_time):.1f} s does not "
                                       f"decode as {topic.type_name} ({exc})")
            return
        result.messages.setdefault(topic.name, []).append(Stamped(message.log_time, decoded))
