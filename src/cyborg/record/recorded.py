"""What every recording to play tells, whatever its format: topics, time span, messages.

:class:`Recording` is the base of the readers (:mod:`cyborg.record.mcap_recording`,
:mod:`cyborg.record.bag_recording`; :func:`cyborg.record.playback_source.open_recording`
chooses one): the topics it can play (:class:`PlayedTopic`), those it cannot with the reason,
its first and last log times, whether it was cut, and its messages as :class:`Played` (topic,
log time, CDR bytes) in log-time order. A :class:`TypeLearner` makes recorded types known to
the bus from the recording's own definitions, within bounds: the time to read a definition
grows with its lines (and faster than them past a few thousand fields), so one holding more than
:data:`MAX_SCHEMA_FIELDS` fields or :data:`MAX_SCHEMA_BYTES` bytes is not read, nor any past
:data:`MAX_LEARNED_FIELDS` fields read for one recording; their topics are skipped, naming the
type and the bound.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import NamedTuple

from cyborg.bus import MessageTypes

MAX_SCHEMA_BYTES = 1024 * 1024
"""Most bytes of one type's definition, comments and the types it uses included (the largest
known to the bus, ``visualization_msgs/msg/InteractiveMarkerUpdate``, takes 4 KB without its
comments)."""
MAX_SCHEMA_FIELDS = 1000
"""Most fields one type's definition may declare, counting its constants and the types it
uses with their own (the largest known to the bus has 112)."""
MAX_LEARNED_FIELDS = 20_000
"""Most fields read from the definitions of one recording, all its types together."""


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


SKIPPED_SHOWN = 10
"""Skipped topics a command's one line names; the rest are counted."""


def skipped_line(skipped: Mapping[str, str], shown: int = SKIPPED_SHOWN) -> str:
    """Topics left out, in one line: ``N topics: /a (why); /b (why); and 3 more``.

    At most ``shown`` are named (a recording may leave out thousands), in name order, each
    reason cut to 200 characters.
    """
    count = len(skipped)
    named = sorted(skipped.items())[:shown]
    listed = "; ".join(f"{topic} ({why[:200]})" for topic, why in named)
    more = f"; and {count - len(named):,} more" if count > len(named) else ""
    return f"{count:,} topic{'s' if count != 1 else ''}: {listed}{more}"


@dataclass
class Recording:
    """A recording opened for play; read its messages with :meth:`messages`.

    The base class holds what every kind of recording tells;
    :class:`~cyborg.record.mcap_recording.McapRecording` and
    :class:`~cyborg.record.bag_recording.BagRecording` read them.
    """

    path: Path
    topics: dict[str, PlayedTopic] = field(default_factory=dict)
    skipped: dict[str, str] = field(default_factory=dict)
    """Topics that are not played, with the reason."""
    unplayed: dict[str, PlayedTopic] = field(default_factory=dict)
    """The topics of :attr:`skipped` as recorded: their type and how many messages they have."""
    metadata: list[tuple[str, dict[str, str]]] = field(default_factory=list)
    """The recording's metadata records (name and values) in file order; none for a bag."""
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

    @property
    def size(self) -> int:
        """Bytes on disk: the file's, or every file's of a bag folder."""
        if self.path.is_dir():
            return sum(item.stat().st_size for item in self.path.iterdir() if item.is_file())
        return self.path.stat().st_size

    def skip(self, topic: PlayedTopic, why: str) -> None:
        """Notes that ``topic`` is not played, and why."""
        self.skipped[topic.name] = why
        self.unplayed[topic.name] = topic

    def messages(self, start_ns: int = 0) -> Iterator[Played]:
        """The messages of the played topics from ``start_ns`` on, in log-time order."""
        raise NotImplementedError

    def latched_before(self, start_ns: int) -> list[Played]:
        """The last message before ``start_ns`` of each latched topic, in log-time order."""
        raise NotImplementedError

    def close(self) -> None:
        """Releases the file."""


def plain_definition(type_name: str, text: str) -> tuple[str, int]:
    """``text`` without its comment and blank lines, and how many fields it declares.

    Its constants and the ``MSG:`` line of each type it uses count as fields. Raises
    ValueError naming the type when ``text`` passes :data:`MAX_SCHEMA_BYTES` or
    :data:`MAX_SCHEMA_FIELDS` (counted line by line, no further than the bound).
    """
    if len(text) > MAX_SCHEMA_BYTES:
        raise ValueError(f"{type_name}: a definition of {len(text):,} characters, more than the "
                         f"{MAX_SCHEMA_BYTES // 2**20} MiB one may hold")
    kept: list[str] = []
    fields = 0
    for line in text.splitlines():
        stripped = line.strip()
        if not stripped or stripped.startswith("#"):
            continue
        kept.append(line)
        if not stripped.startswith("="):  # the line of = between two types' definitions
            fields += 1
            if fields > MAX_SCHEMA_FIELDS:
                raise ValueError(f"{type_name}: a definition of more than "
                                 f"{MAX_SCHEMA_FIELDS:,} fields, the most one may declare "
                                 "(its constants and the types it uses counted)")
    return "\n".join(kept) + "\n", fields


class TypeLearner:
    """Makes recorded types known to ``types``: one per recording, see the module.

    It reads no more than :data:`MAX_LEARNED_FIELDS` fields of definitions in all. Callers
    ask once per definition (a schema, a type): a definition that cannot be read is read again
    each time it is asked for, and counted again.
    """

    def __init__(self, types: MessageTypes) -> None:
        self.types = types
        self.fields_left = MAX_LEARNED_FIELDS

    def learn(self, type_name: str, definition: str) -> str | None:
        """Makes ``type_name`` known from ``definition`` if the bus does not know it.

        Returns None when the bus knows it (now), else why it cannot be played, in one line
        naming the type.
        """
        if type_name in self.types:
            return None
        try:
            plain, fields = plain_definition(type_name, definition)
        except ValueError as exc:
            return str(exc)
        if not definition.strip():
            return f"unknown type {type_name}, and the recording holds no definition of it"
        if fields > self.fields_left:
            return (f"{type_name}: its definition's {fields:,} fields would pass the "
                    f"{MAX_LEARNED_FIELDS:,} read for one recording")
        self.fields_left -= fields
        try:
            self.types.add_definition(type_name, plain)
        except ValueError as exc:
            reason = str(exc)
            first = reason.splitlines()[0]  # a parser's report of the text runs over lines
            return first if first == reason else first.split(" (")[0]
        return None if type_name in self.types else f"unknown type {type_name}"


def is_latched(qos_yaml: str) -> bool:
    """Whether the ``offered_qos_profiles`` of a rosbag2 channel name a transient-local one."""
    return "transient_local" in qos_yaml
