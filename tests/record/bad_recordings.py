"""Files that are no recording, or not a whole or fully known one, as a user hands them over.

Shared by the tests of ``cyborg play`` (tests/app), ``cyborg report`` (tests/report) and the
readers and ``--recover`` (tests/record): each ``refused`` case is a path and the words its one
line of error must hold; the other makers write recordings that play only in part.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from mcap.writer import Writer
from rosbags.rosbag1 import Writer as Ros1Writer
from rosbags.rosbag2 import StoragePlugin
from rosbags.rosbag2 import Writer as Ros2Writer
from rosbags.typesys import Stores, get_typestore

from cyborg.bus import MessageTypes
from cyborg.bus.msgs.std_msgs.msg import String
from cyborg.record.bag_checks import (
    MAX_BAG_FILES,
    MAX_BAG_TOPICS,
    MAX_METADATA_BYTES,
    MAX_METADATA_VALUES,
)
from cyborg.record.scan import BYTES_PER_CHANNEL, MAX_CHANNELS, scan

STRING = "std_msgs/msg/String"


def ros1_bag(path: Path) -> Path:
    """A real ROS 1 bag (rosbags' rosbag1 writer) written at ``path``, whatever its suffix."""
    store = get_typestore(Stores.ROS1_NOETIC)
    with Ros1Writer(path) as writer:
        chatter = writer.add_connection("/chatter", STRING, typestore=store)
        writer.write(chatter, 1_000, store.serialize_ros1(store.types[STRING](data="hi"), STRING))
    return path


def sqlite_bag(folder: Path, messages: int = 3) -> Path:
    """A ROS 2 bag folder (``metadata.yaml`` and a ``.db3``) of ``messages`` strings."""
    store = get_typestore(Stores.ROS2_HUMBLE)
    with Ros2Writer(folder, version=9, storage_plugin=StoragePlugin.SQLITE3) as writer:
        chatter = writer.add_connection("/chatter", STRING, typestore=store)
        for number in range(messages):
            writer.write(chatter, 1_000 + number, bytes(store.serialize_cdr(
                store.types[STRING](data=f"message {number}"), STRING)))
    return folder


def _sqlite_as_mcap(folder: Path) -> Path:
    bag = sqlite_bag(folder / "bag")
    return (bag / "bag.db3").rename(folder / "run.mcap")


def _folder(path: Path) -> Path:
    path.mkdir()
    return path


def _write(path: Path, content: bytes) -> Path:
    path.write_bytes(content)
    return path


def wide(fields: int, *, comments: int = 0) -> str:
    """A definition of ``fields`` int32 fields, after ``comments`` lines of comment."""
    return "# a comment\n" * comments + "".join(f"int32 f{number}\n" for number in range(fields))


def many_channels(path: Path, channels: int = MAX_CHANNELS + 1, *, chunk_size: int = 1024 * 1024,
                  cut: bool = False) -> Path:
    """An MCAP file defining ``channels`` channels of one schema, no message on them but one on
    the first; ``cut`` keeps only its first chunk (no summary repeats the channels then)."""
    with open(path, "wb") as stream:
        writer = Writer(stream, chunk_size=chunk_size)
        writer.start(profile="ros2", library="test")
        schema = writer.register_schema(STRING, "ros2msg", b"string data\n")
        ids = [writer.register_channel(f"/t{number}", "cdr", schema)
               for number in range(channels)]
        writer.add_message(ids[0], 1_000, b"\x00\x01\x00\x00\x01\x00\x00\x00\x00", 1_000)
        writer.finish()
    if cut:
        first = scan(path).chunks[0]
        with open(path, "r+b") as stream:
            stream.truncate(first.offset + first.length)
    return path


REFUSED: dict[str, tuple[Callable[[Path], Path], str]] = {
    "empty": (lambda d: _write(d / "run.mcap", b""), "the file is empty"),
    "text": (lambda d: _write(d / "run.mcap", b"time,x,y\n0,1,2\n"), "a text file"),
    "ros1 bag named .mcap": (lambda d: ros1_bag(d / "run.mcap"), "a ROS 1 bag"),
    "sqlite named .mcap": (lambda d: _sqlite_as_mcap(d), "an SQLite database"),
    "cut in its header": (lambda d: _write(d / "run.mcap", b"\x89MCAP0\r\n\x01\x20\x00"),
                          "cut before the end of its header"),
    "missing": (lambda d: d / "none.mcap", "no such file"),
    "folder": (lambda d: _folder(d / "notes"), "a folder"),
    "too many channels": (lambda d: many_channels(d / "run.mcap"),
                          f"more than the {MAX_CHANNELS:,} channels a recording may define "
                          "(channel 10001 in the chunk at byte "),
    "more channels than its size holds": (
        lambda d: many_channels(d / "run.mcap", 3000, chunk_size=2**22, cut=True),
        f"more than one per {BYTES_PER_CHANNEL} bytes of the file (channel "),
}
"""Input refused by play, report and --recover alike: how to make it, and what is said."""


def _bag(folder: Path, metadata: str) -> Path:
    """A bag folder whose ``metadata.yaml`` is ``metadata``."""
    folder.mkdir()
    (folder / "metadata.yaml").write_text(metadata)
    return folder


def bag_metadata(files: int = 1, topics: int = 1) -> str:
    """A rosbag2 ``metadata.yaml`` listing ``files`` files and ``topics`` topics."""
    return ("rosbag2_bagfile_information:\n  version: 9\n  storage_identifier: mcap\n"
            "  duration: {nanoseconds: 1}\n  starting_time: {nanoseconds_since_epoch: 1}\n"
            "  message_count: 1\n  topics_with_message_count:\n"
            + "".join(f"  - {{topic_metadata: {{name: /t{number}, type: {STRING}, "
                      "serialization_format: cdr}, message_count: 0}\n"
                      for number in range(topics))
            + "  relative_file_paths: [" + ", ".join(f"b_{number}.mcap" for number in range(files))
            + "]\n")


def _laughs(levels: int) -> str:
    """YAML of a few hundred bytes whose aliases of aliases name 10 ** ``levels`` values."""
    lines = ["l0: &l0 [x, x, x, x, x, x, x, x, x, x]"]
    lines += [f"l{n}: &l{n} [{', '.join([f'*l{n - 1}'] * 10)}]" for n in range(1, levels)]
    return "\n".join(lines) + "\n"


BAD_BAGS: dict[str, tuple[Callable[[Path], Path], str]] = {
    "a list 5,000 deep": (lambda d: _bag(d / "bag", "[" * 5000 + "]" * 5000),
                          "metadata.yaml: line 1, column 33: nested deeper than 32 levels"),
    "5,000 missing files": (lambda d: _bag(d / "bag", bag_metadata(files=5000)),
                            f"metadata.yaml: lists 5,000 files, more than the {MAX_BAG_FILES:,} "
                            "a bag may hold"),
    "missing files": (lambda d: _bag(d / "bag", bag_metadata(files=MAX_BAG_FILES)),
                      f"bag: {MAX_BAG_FILES:,} of the {MAX_BAG_FILES:,} files metadata.yaml "
                      f"lists are missing: b_0.mcap, b_1.mcap, b_2.mcap and "
                      f"{MAX_BAG_FILES - 3:,} more"),
    "a syntax error": (lambda d: _bag(d / "bag", "rosbag2_bagfile_information:\n"
                                                 "  version: [9\n  x: 1\n"),
                       "metadata.yaml: line 3, column 4: did not find expected ',' or ']' "
                       "(while parsing a flow sequence from line 2, column 12)"),
    "aliases of aliases": (lambda d: _bag(d / "bag", _laughs(9)),
                           f"metadata.yaml: more than {MAX_METADATA_VALUES:,} values, its "
                           "aliases counted as copies of what they name"),
    "too many topics": (lambda d: _bag(d / "bag", bag_metadata(topics=MAX_BAG_TOPICS + 1)),
                        f"metadata.yaml: lists {MAX_BAG_TOPICS + 1:,} topics, more than the "
                        f"{MAX_BAG_TOPICS:,} a bag may hold"),
    "too large": (lambda d: _bag(d / "bag", "#" * MAX_METADATA_BYTES + "\n"),
                  f"metadata.yaml: {MAX_METADATA_BYTES + 1:,} bytes, more than the "
                  f"{MAX_METADATA_BYTES // 2**20} MiB a bag's metadata may hold"),
    "an integer of 5,000 digits": (lambda d: _bag(d / "bag", "a: " + "1" * 5000 + "\n"),
                                   "metadata.yaml: not YAML (Exceeds the limit (4300 digits)"),
}
"""ROS 2 bag folders refused by play and report (``--recover`` refuses every folder): how to
make one in a folder, and what its one line of error says."""


def refused(name: str, folder: Path) -> tuple[Path, str]:
    """The refused input ``name`` of :data:`REFUSED`, made in ``folder``, and what is said."""
    make, said = REFUSED[name]
    return make(folder), said


def small_recording(path: Path, *, chatter: int = 20, extra: Callable[[Writer], None] | None
                    = None) -> Path:
    """An MCAP file with ``chatter`` strings on ``/chatter`` in chunks of five; ``extra`` may
    register and write more before it is finished."""
    types = MessageTypes()
    with open(path, "wb") as stream:
        writer = Writer(stream, chunk_size=200)
        writer.start(profile="ros2", library="test")
        schema = writer.register_schema(STRING, "ros2msg", b"string data\n")
        channel = writer.register_channel("/chatter", "cdr", schema)
        if extra is not None:
            extra(writer)
        for number in range(chatter):
            data = bytes(types.serialize(String(data=f"message {number}"), STRING))
            writer.add_message(channel, 1_000_000_000 + number * 1_000_000, data,
                               1_000_000_000 + number * 1_000_000)
        writer.finish()
    return path


def with_strange_schemas(path: Path) -> Path:
    """A recording whose ``/chatter`` plays, beside topics whose schema is unknown, empty,
    without a name, missing (schema id 0) or undecodable."""
    def strange(writer: Writer) -> None:
        channels = [
            writer.register_channel("/unknown", "cdr", writer.register_schema(
                "their_msgs/msg/Thing", "ros2msg", b"their_msgs/Part part\n")),
            writer.register_channel("/empty", "cdr", writer.register_schema(
                "their_msgs/msg/Empty", "ros2msg", b"")),
            writer.register_channel("/nameless", "cdr", writer.register_schema(
                "", "ros2msg", b"int32 x\n")),
            writer.register_channel("/schemaless", "cdr", 0),
            writer.register_channel("/garbled", "cdr", writer.register_schema(
                "their_msgs/msg/Garbled", "ros2msg", b"\xff\xfe this is { not a msg\n")),
        ]
        for channel in channels:
            writer.add_message(channel, 1_000_000_000, b"\x00\x01\x00\x00", 1_000_000_000)
    return small_recording(path, extra=strange)


STRANGE_TOPICS = {"/unknown": "their_msgs/msg/Part, defined nowhere", "/empty": "no definition",
                  "/nameless": "without a type name", "/schemaless": "no schema",
                  "/garbled": "their_msgs/msg/Garbled"}
"""The topics :func:`with_strange_schemas` cannot play, and a word of why."""


def cut_in_its_middle(whole: Path, target: Path) -> Path:
    """``whole`` cut in the middle of its middle chunk (as kill -9 leaves a file)."""
    chunks = scan(whole).chunks
    middle = chunks[len(chunks) // 2]
    target.write_bytes(whole.read_bytes()[:middle.offset + middle.length // 2])
    return target
