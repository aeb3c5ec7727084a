"""A recording read back for a report: its topics, its metadata and the messages a report uses.

:func:`read_recording` opens the file with :func:`cyborg.record.playback_source.open_recording`,
the reader ``cyborg play`` uses, so a report reads whatever plays: an MCAP file, whole or cut by
``kill -9`` or a power loss (read up to its last whole record, and the report says it was cut,
:attr:`Recording.cut`), a ROS 1 bag or a ROS 2 bag folder. What is no recording (empty, a ROS 1
bag or a text file named ``.mcap``, a file cut inside its header, a missing file, a folder that
is no bag) is refused with :class:`~cyborg.record.playback_source.RecordingError` naming the
file and what is wrong.

Every message is counted; only those a report draws are decoded (``wanted(topic, type)``;
of a topic in ``every``, one message per so many nanoseconds of log time and the last: a
simulator's ``/clock`` comes thousands of times a second), with the bus's own message types
(:class:`cyborg.bus.MessageTypes`, which learn a type the bus does not know from the
recording's own definition), from the CDR bytes as they travelled.
A topic that cannot be read (an unknown type with no usable definition, another encoding), or
a message that does not decode, is kept as a note in :attr:`Recording.problems`, never an
error: the rest is still reported.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from cyborg.bus import MessageTypes
from cyborg.record.playback_source import Recording as Source
from cyborg.record.playback_source import open_recording

MAX_PROBLEMS_PER_TOPIC = 3
"""Decoding problems noted for one topic; the rest are only counted."""


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
    skipped: dict[str, str] = field(default_factory=dict)
    """Topics that could not be read at all, with the reason (also among :attr:`problems`)."""

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


def read_recording(path: Path, wanted: Callable[[str, str], bool],
                   types: MessageTypes | None = None, every: Mapping[str, int] | None = None
                   ) -> Recording:
    """Reads ``path``; see the module. RecordingError names the file and what is wrong."""
    types = types or MessageTypes()
    source = open_recording(path, types)
    try:
        result = Recording(path, source.size, metadata=list(source.metadata),
                           start=source.start_ns, end=source.end_ns, cut=source.cut or "")
        for topic in sorted([*source.topics.values(), *source.unplayed.values()],
                            key=lambda topic: topic.name):
            result.topics[topic.name] = TopicRecord(topic.name, topic.type_name, topic.count)
        result.skipped = dict(sorted(source.skipped.items()))
        for name, why in result.skipped.items():
            result.problems.append(f"{name}: {why}; not read")
        _decode(source, result, wanted, types, every or {})
    finally:
        source.close()
    return result


def _decode(source: Source, result: Recording, wanted: Callable[[str, str], bool],
            types: MessageTypes, every: Mapping[str, int]) -> None:
    """Decodes the messages of the wanted topics into ``result`` (sampled as ``every`` says)."""
    decoded = {name for name, topic in source.topics.items() if wanted(name, topic.type_name)}
    failures: dict[str, int] = {}
    taken: dict[str, int] = {}  # log time of the last message decoded, per sampled topic
    passed: dict[str, Any] = {}  # the last message passed over, per sampled topic
    for played in source.messages():
        if played.topic not in decoded:
            continue
        gap = every.get(played.topic)
        if gap is not None:
            if played.log_time - taken.get(played.topic, -gap) < gap:
                passed[played.topic] = played
                continue
            taken[played.topic] = played.log_time
            passed.pop(played.topic, None)
        _decode_one(source, result, types, played, failures)
    for played in passed.values():  # a sampled topic's last message, unless taken already
        _decode_one(source, result, types, played, failures)


def _decode_one(source: Source, result: Recording, types: MessageTypes, played: Any,
                failures: dict[str, int]) -> None:
    """Decodes one message into ``result``, or notes (the first few times) why it does not."""
    type_name = source.topics[played.topic].type_name
    try:
        message = types.deserialize(played.data, type_name)
    except Exception as exc:  # a message the recording holds but our type cannot read
        failed = failures[played.topic] = failures.get(played.topic, 0) + 1
        if failed <= MAX_PROBLEMS_PER_TOPIC:
            result.problems.append(f"{played.topic}: a message at "
                                   f"{result.seconds(played.log_time):.1f} s does not "
                                   f"decode as {type_name} ({exc})")
        return
    result.messages.setdefault(played.topic, []).append(Stamped(played.log_time, message))
