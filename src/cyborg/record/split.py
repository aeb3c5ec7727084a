"""A recording's files: one, or a series split by size or by duration.

Without a split the recording is the one file named (``run.mcap``). With ``--split-size`` or
``--split-duration`` it is a rosbag2 bag folder, as ``ros2 bag record -o run`` writes one: the
name without its suffix is the folder (``run/``), its files are named as rosbag2 names them, the
index before the suffix from 0 (``run/run_0.mcap``, ``run/run_1.mcap``, ...), and its
``metadata.yaml`` lists them all with their topics, counts and times
(:mod:`cyborg.record.bag_metadata`), written again each time a file is closed, so ``cyborg
play run/``, ``ros2 bag play run/`` and rosbags' ``AnyReader`` read the series as one
recording. A new file starts before the message that
would go over the limit is written, between two messages on the recorder's one writing thread,
so no message is lost or written twice at a split. Every file is complete on its own: it
repeats the schemas, the channels of every topic recorded so far and the metadata, so each
opens alone in Foxglove or ``ros2 bag``. Latched messages are not repeated: a file after the
first holds the latched topics' messages only if they were published again during it.
"""

from __future__ import annotations

import logging
import re
import time
from dataclasses import dataclass, field
from pathlib import Path

from cyborg.bus import MessageTypes
from cyborg.record.bag_metadata import FOLDER_FILE, FileSummary, write_folder_metadata
from cyborg.record.guarded_stream import StorageError
from cyborg.record.mcap_file import McapFile

log = logging.getLogger(__name__)

_SIZE = re.compile(r"^\s*(\d+(?:\.\d+)?)\s*([KMGT]?i?B?)\s*$", re.IGNORECASE)
_SIZE_UNITS = {"": 1, "B": 1, "K": 1e3, "KB": 1e3, "M": 1e6, "MB": 1e6, "G": 1e9, "GB": 1e9,
               "T": 1e12, "TB": 1e12, "KIB": 2**10, "MIB": 2**20, "GIB": 2**30, "TIB": 2**40}
_DURATION = re.compile(r"^\s*(\d+(?:\.\d+)?)\s*(s|m|min|h)?\s*$", re.IGNORECASE)
_DURATION_UNITS = {"": 1, "s": 1, "m": 60, "min": 60, "h": 3600}
MIN_SPLIT_SIZE = 1024 * 1024
"""The smallest split size: a file holds at least a chunk."""


def parse_size(text: str) -> int:
    """``1GiB``, ``500MB``, ``2G`` -> bytes; ValueError naming the option for anything else."""
    match = _SIZE.match(text)
    if not match or match.group(2).upper() not in _SIZE_UNITS:
        raise ValueError(f"--split-size {text!r}: expected a size such as 500MB or 1GiB")
    size = int(float(match.group(1)) * _SIZE_UNITS[match.group(2).upper()])
    if size < MIN_SPLIT_SIZE:
        raise ValueError(f"--split-size {text!r}: at least 1MiB")
    return size


def parse_duration(text: str) -> float:
    """``10m``, ``90s``, ``1h``, ``30`` (seconds) -> seconds; ValueError naming the option."""
    match = _DURATION.match(text)
    if not match:
        raise ValueError(f"--split-duration {text!r}: expected a duration such as 90s, 10m "
                         "or 1h")
    seconds = float(match.group(1)) * _DURATION_UNITS[(match.group(2) or "").lower()]
    if seconds <= 0:
        raise ValueError(f"--split-duration {text!r}: must be more than 0")
    return seconds


def split_folder(path: Path) -> Path:
    """The bag folder of a split recording named ``path``: ``run.mcap`` -> ``run/``."""
    return path.with_name(path.stem if path.suffix else path.name)


def split_name(path: Path, index: int) -> Path:
    """The name of file ``index`` of a split recording: ``run.mcap`` -> ``run/run_0.mcap``."""
    folder = split_folder(path)
    return folder / f"{folder.name}_{index}{path.suffix or '.mcap'}"


@dataclass(frozen=True)
class SplitPolicy:
    """When a new file starts: past ``size`` bytes or ``duration`` seconds (None: never)."""

    size: int | None = None
    duration: float | None = None

    @property
    def splits(self) -> bool:
        """Whether the recording is a series of files."""
        return self.size is not None or self.duration is not None


@dataclass
class _Topic:
    type_name: str
    offered_qos: list[str]


@dataclass
class RecordingFiles:
    """The files of one recording; writes go to the current one, which rolls over by policy.

    ``path`` is the name given (``run.mcap``); every path this recording wrote is in
    :attr:`paths`, the current one last. A file, or a split recording's folder, that exists
    already is refused (FileExistsError naming it) before anything is written.
    """

    path: Path
    types: MessageTypes
    compression: str = "zstd"
    policy: SplitPolicy = field(default_factory=SplitPolicy)
    paths: list[Path] = field(init=False, default_factory=list)
    _topics: dict[str, _Topic] = field(init=False, default_factory=dict)
    _metadata: dict[tuple[str, str], dict[str, str]] = field(init=False, default_factory=dict)
    _current: McapFile | None = field(init=False, default=None)
    _opened: float = field(init=False, default=0.0)
    _closed: list[FileSummary] = field(init=False, default_factory=list)

    def __post_init__(self) -> None:
        first = self.path
        if self.policy.splits:
            first = split_name(self.path, 0)
            if first.parent.exists():
                raise FileExistsError(f"{first.parent} exists already; choose another name or "
                                      "remove it")
            first.parent.mkdir()
        elif first.exists():
            raise FileExistsError(f"{first} exists already; choose another name or remove it")
        self._open(first)

    @property
    def folder(self) -> Path | None:
        """The bag folder of a split recording (None for one file)."""
        return split_folder(self.path) if self.policy.splits else None

    @property
    def current(self) -> McapFile:
        """The file being written now."""
        assert self._current is not None
        return self._current

    def _open(self, path: Path) -> None:
        try:
            self._current = McapFile(path, self.types, compression=self.compression)
        except FileExistsError as exc:
            if not self.paths:
                raise
            raise StorageError(f"{path} exists already; the recording stopped before it "
                               "rather than overwrite it") from exc
        self.paths.append(path)
        self._opened = time.monotonic()
        for (name, _topic), values in self._metadata.items():
            self._current.metadata(name, values)
        for topic, known in self._topics.items():
            self._current.channel(topic, known.type_name, known.offered_qos)

    def add_topic(self, topic: str, type_name: str, offered_qos: list[str]) -> None:
        """Makes ``topic`` a channel of this and every later file."""
        self._topics[topic] = _Topic(type_name, offered_qos)
        self.current.channel(topic, type_name, offered_qos)

    def add_metadata(self, name: str, values: dict[str, str]) -> None:
        """Adds a metadata record to this file; later files repeat the last of each name.

        Records that name a ``topic`` are told apart by it too: each robot's map is repeated.
        """
        self._metadata[(name, values.get("topic", ""))] = values
        self.current.metadata(name, values)

    def write(self, topic: str, log_time: int, publish_time: int, data: bytes) -> None:
        """Writes one message of a topic added before, starting a new file first if due."""
        if self._due(len(data)):
            self._finish_current()
            self._open(split_name(self.path, len(self.paths)))
        current = self.current
        current.write(current.channel_of(topic), log_time, publish_time, data)

    def _due(self, incoming: int) -> bool:
        policy, current = self.policy, self.current
        if not current.messages:
            return False
        if policy.size is not None and current.size + incoming > policy.size:
            return True
        return (policy.duration is not None
                and time.monotonic() - self._opened >= policy.duration)

    def flush_if_due(self) -> None:
        """Writes and syncs the open chunk if it is old enough (see :mod:`.mcap_file`)."""
        self.current.flush_if_due()

    def close(self) -> None:
        """Finishes the current file (and a split recording's ``metadata.yaml``)."""
        if self._current is not None and not self._current.closed:
            self._finish_current()

    def _finish_current(self) -> None:
        """Closes the current file; a split recording's folder describes it from then on."""
        current = self.current
        current.close()
        folder = self.folder
        if folder is None:
            return
        self._closed.append(current.summary)
        try:
            write_folder_metadata(folder, self._closed, current.custom_data)
        except OSError as exc:  # a full disk: the files stand alone, each with its own record
            log.error("%s: cannot be written: %s", folder / FOLDER_FILE, exc.strerror or exc)
