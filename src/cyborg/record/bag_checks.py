"""A bag checked against bounds before rosbags reads it, so that no bag can hold it up for long.

rosbags' ``AnyReader`` (:mod:`cyborg.record.bag_recording`) reads a ROS 2 bag folder's
``metadata.yaml`` with a YAML parser written in Python (about 7 s a megabyte, recursing once
for each level of nesting), looks every file it lists up, compares each topic with each
channel of the storage files, and reads the definition of every topic's type, once for each
topic. A hostile folder could make each of these take minutes, or end in a RecursionError;
:func:`check_folder` and :func:`check_ros1` refuse it first, with :class:`RecordingError`
naming the file and, where there is one, the line and column:

* ``metadata.yaml`` holds at most :data:`MAX_METADATA_BYTES`, nests at most
  :data:`MAX_METADATA_DEPTH` levels, holds at most :data:`MAX_METADATA_VALUES` values with
  each alias counted as a copy of what it names (as a reader goes through it: aliases of
  aliases make billions of a few bytes), and parses (a syntax error is said in one line, with
  its line and column);
* it lists at most :data:`MAX_BAG_FILES` files and :data:`MAX_BAG_TOPICS` topics; files that
  are missing are counted, and the first :data:`NAMED_MISSING` named;
* its storage files (and a ROS 1 bag) define at most
  :data:`~cyborg.record.scan.MAX_CHANNELS` channels together, no definition that rosbags will
  read passes the bounds of :func:`~cyborg.record.recorded.plain_definition`, and all it will
  read hold at most :data:`MAX_DEFINITION_LINES` lines.

The file is parsed here with libyaml's parser (C) where PyYAML has it, event by event, so the
depth is known before anything recurses.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from contextlib import suppress
from pathlib import Path, PurePath
from typing import Any

import yaml
from rosbags.interfaces import Connection, MessageDefinitionFormat
from rosbags.rosbag1 import Reader as Ros1Reader
from rosbags.rosbag2.reader import DirectoryReader

from cyborg.record.recorded import RecordingError, plain_definition
from cyborg.record.scan import MAX_CHANNELS

MAX_METADATA_BYTES = 1024 * 1024
"""Most bytes of a bag's ``metadata.yaml`` (a bag of 100 topics and 1,000 files takes about
250 KB)."""
MAX_METADATA_DEPTH = 32
"""Most levels of nesting in ``metadata.yaml`` (rosbag2 writes 7)."""
MAX_METADATA_VALUES = 500_000
"""Most values (scalars, lists, mappings) in ``metadata.yaml``, aliases counted as copies."""
MAX_BAG_FILES = 1000
"""Most files one bag folder may list."""
MAX_BAG_TOPICS = 1000
"""Most topics one bag folder may list."""
MAX_DEFINITION_LINES = 100_000
"""Most lines of type definitions rosbags reads for one bag, every topic's counted."""
NAMED_MISSING = 3
"""Missing files named in the error; the rest are counted."""

_LOADER: Any = getattr(yaml, "CSafeLoader", yaml.SafeLoader)


def check_folder(folder: Path) -> None:
    """Checks the bag folder ``folder`` against the module's bounds; RecordingError if not."""
    path = folder / "metadata.yaml"
    information = _information(read_metadata(path))
    names = information.get("relative_file_paths")
    if not isinstance(names, list):
        return  # rosbags says what is wrong with the metadata itself
    if len(names) > MAX_BAG_FILES:
        raise RecordingError(f"{path}: lists {len(names):,} files, more than the "
                             f"{MAX_BAG_FILES:,} a bag may hold")
    topics = information.get("topics_with_message_count")
    if isinstance(topics, list) and len(topics) > MAX_BAG_TOPICS:
        raise RecordingError(f"{path}: lists {len(topics):,} topics, more than the "
                             f"{MAX_BAG_TOPICS:,} a bag may hold")
    files = [folder / PurePath(name).name for name in names if isinstance(name, str)]
    missing = [file.name for file in files if not file.exists()]
    if missing:
        named = ", ".join(missing[:NAMED_MISSING])
        more = len(missing) - NAMED_MISSING
        raise RecordingError(
            f"{folder}: {len(missing):,} of the {len(names):,} files metadata.yaml lists "
            f"{'is' if len(missing) == 1 else 'are'} missing: {named}"
            + (f" and {more:,} more" if more > 0 else ""))
    for file in files:
        if not file.is_file():
            raise RecordingError(f"{file}: listed in metadata.yaml, but not a regular file")
    plugin = DirectoryReader.STORAGE_PLUGINS.get(str(information.get("storage_identifier")))
    if plugin is None or not isinstance(topics, list):
        return
    connections: list[Connection] = []
    for file in files:
        connections.extend(_connections(plugin(file), len(connections), file))
    read = [_type_of(topic) for topic in topics]
    _check_definitions(folder, connections, read)


def check_ros1(path: Path) -> None:
    """Checks the ROS 1 bag ``path``: its channels and definitions; RecordingError if not."""
    connections = _connections(Ros1Reader(path), 0, path)
    _check_definitions(path, connections, [(c.topic, c.msgtype) for c in connections])


def read_metadata(path: Path) -> object:
    """``metadata.yaml`` at ``path`` parsed, once it is known to be within bounds.

    Raises RecordingError naming the file, and the line and column where there are some,
    for a file too large, not UTF-8, nested too deep, not YAML, or of too many values.
    """
    try:
        size = path.stat().st_size
        if size > MAX_METADATA_BYTES:
            raise RecordingError(f"{path}: {size:,} bytes, more than the "
                                 f"{MAX_METADATA_BYTES // 2**20} MiB a bag's metadata may hold")
        data = path.read_bytes()[:MAX_METADATA_BYTES + 1]
    except OSError as exc:
        raise RecordingError(f"{path}: cannot be read ({exc.strerror or exc})") from None
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise RecordingError(f"{path}: not UTF-8 text (byte {exc.start})") from None
    try:
        _check_events(path, yaml.parse(text, Loader=_LOADER))
        data = yaml.load(text, Loader=_LOADER)  # a safe loader: plain data only
    except RecordingError:
        raise
    except yaml.MarkedYAMLError as exc:
        raise RecordingError(f"{path}: {_located(exc)}") from None
    except (yaml.YAMLError, ValueError) as exc:  # ValueError: an integer of 5,000 digits
        raise RecordingError(f"{path}: not YAML ({_one_line(str(exc))})") from None
    if _values(data, MAX_METADATA_VALUES) > MAX_METADATA_VALUES:
        raise RecordingError(f"{path}: more than {MAX_METADATA_VALUES:,} values, its aliases "
                             "counted as copies of what they name")
    return data


def _values(data: object, most: int) -> int:
    """How many values ``data`` holds, shared ones counted each time; no more than ``most``+1.

    Goes through ``data`` as a reader would, with a stack of its own (an alias can make a
    list hold itself), and stops once past ``most``.
    """
    counted, pending = 0, [data]
    while pending and counted <= most:
        value = pending.pop()
        counted += 1
        if isinstance(value, dict):
            pending.extend(value.keys())
            pending.extend(value.values())
        elif isinstance(value, list):
            pending.extend(value)
    return counted


def _check_events(path: Path, events: Iterator[yaml.Event]) -> None:
    """Goes through the parser's events: no deeper than the bound."""
    depth = 0
    for event in events:
        if isinstance(event, yaml.CollectionStartEvent):
            depth += 1
            if depth > MAX_METADATA_DEPTH:
                raise RecordingError(f"{path}: {_at(event)}: nested deeper than "
                                     f"{MAX_METADATA_DEPTH} levels")
        elif isinstance(event, yaml.CollectionEndEvent):
            depth -= 1


def _at(event: yaml.Event) -> str:
    """Where ``event`` starts: ``line 3, column 4``."""
    return _mark(event.start_mark)


def _located(error: yaml.MarkedYAMLError) -> str:
    """A YAML syntax error in one line: where, what is wrong there, and in what."""
    said = _one_line(error.problem or "not YAML")
    if error.problem_mark is not None:
        said = f"{_mark(error.problem_mark)}: {said}"
    if error.context:
        begun = f" from {_mark(error.context_mark)}" if error.context_mark is not None else ""
        said += f" ({_one_line(error.context)}{begun})"
    return said


def _mark(mark: yaml.Mark) -> str:
    """A place in the file, counted from 1: ``line 3, column 4``."""
    return f"line {mark.line + 1}, column {mark.column + 1}"


def _one_line(text: str) -> str:
    """``text`` with its line breaks and runs of spaces made single spaces."""
    return " ".join(text.split())


def _information(data: object) -> dict[str, Any]:
    """The ``rosbag2_bagfile_information`` mapping (empty when there is none)."""
    information = data.get("rosbag2_bagfile_information") if isinstance(data, dict) else None
    return information if isinstance(information, dict) else {}


def _type_of(topic: object) -> tuple[str, str]:
    """A topic of ``topics_with_message_count``: its name and type ("" where not given)."""
    metadata = topic.get("topic_metadata") if isinstance(topic, dict) else None
    if not isinstance(metadata, dict):
        return "", ""
    return str(metadata.get("name", "")), str(metadata.get("type", ""))


def _connections(reader: Any, before: int, path: Path) -> list[Connection]:
    """The channels of a storage file or ROS 1 bag, opened with rosbags' own reader.

    A file the reader cannot open gives none (rosbags says why when it reads the bag).
    ``before`` channels were found in the bag's earlier files.
    """
    try:
        reader.open()
    except Exception:  # said by rosbags when the bag is read
        return []
    try:
        connections = list(reader.connections)
    finally:
        with suppress(Exception):
            reader.close()
    if before + len(connections) > MAX_CHANNELS:
        raise RecordingError(f"{path}: more than the {MAX_CHANNELS:,} channels a recording may "
                             f"define ({before + len(connections):,} in the bag up to here)")
    return connections


def _check_definitions(where: Path, connections: Iterable[Connection],
                       read: list[tuple[str, str]]) -> None:
    """Checks the definitions rosbags will read: one for each of ``read`` (topic, type)."""
    definitions: dict[str, str] = {}
    for connection in connections:
        if connection.msgdef.format != MessageDefinitionFormat.NONE:
            definitions.setdefault(connection.msgtype, connection.msgdef.data)
    checked: set[str] = set()
    lines = 0
    for topic, type_name in read:
        text = definitions.get(type_name, "")
        if not text:
            continue  # no definition: rosbags reads none
        if type_name not in checked:
            checked.add(type_name)
            try:
                plain_definition(type_name, text)
            except ValueError as exc:
                raise RecordingError(f"{where}: topic {topic}: {exc}") from None
        lines += text.count("\n") + 1
        if lines > MAX_DEFINITION_LINES:
            raise RecordingError(f"{where}: the definitions of its topics, each read once for "
                                 f"each topic, pass {MAX_DEFINITION_LINES:,} lines (at topic "
                                 f"{topic})")
