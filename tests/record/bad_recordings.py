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
from cyborg.record.scan import scan

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


REFUSED: dict[str, tuple[Callable[[Path], Path], str]] = {
    "empty": (lambda d: _write(d / "run.mcap", b""), "the file is empty"),
    "text": (lambda d: _write(d / "run.mcap", b"time,x,y\n0,1,2\n"), "a text file"),
    "ros1 bag named .mcap": (lambda d: ros1_bag(d / "run.mcap"), "a ROS 1 bag"),
    "sqlite named .mcap": (lambda d: _sqlite_as_mcap(d), "an SQLite database"),
    "cut in its header": (lambda d: _write(d / "run.mcap", b"\x89MCAP0\r\n\x01\x20\x00"),
                          "cut before the end of its header"),
    "missing": (lambda d: d / "none.mcap", "no such file"),
    "folder": (lambda d: _folder(d / "notes"), "a folder"),
}
"""Input refused by play, report and --recover alike: how to make it, and what is said."""


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
