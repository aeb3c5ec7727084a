"""A full disk stops a recording with a message naming the file and the reason, and leaves a
readable, indexed file holding what was written before."""

from __future__ import annotations

import errno
import io
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from mcap.reader import make_reader

from cyborg.bus import BusConfig, Context, MessageTypes, Node
from cyborg.bus.msgs.std_msgs.msg import String
from cyborg.bus.wire import EntityKind
from cyborg.record import completion, mcap_file, split
from cyborg.record.guarded_stream import StorageError
from cyborg.record.mcap_file import McapFile
from cyborg.record.recorder import Recorder
from cyborg.record.selection import TopicSelection
from cyborg.record.split import RecordingFiles
from tests.bus.bus_peer import wait_for
from tests.record.readers import raw_messages

TYPES = MessageTypes()


class FullDisk(io.FileIO):
    """A file on a disk with ``room`` bytes left: a write beyond it is cut short by ENOSPC."""

    def __init__(self, path: Path, room: int) -> None:
        super().__init__(path, "xb")
        self.room = room

    def write(self, data: Any) -> int:
        left = self.room - self.tell()
        if len(data) > left:
            if left > 0:
                super().write(bytes(data)[:left])
            raise OSError(errno.ENOSPC, "No space left on device")
        return super().write(data)


def fill(file: McapFile, count: int) -> None:
    channel = file.channel("/log", "std_msgs/msg/String", [])
    for i in range(count):
        data = bytes(TYPES.serialize(String(data=f"{i:06d}" + "x" * 200), "std_msgs/msg/String"))
        file.write(channel, 10**18 + i, 10**18 + i, data)
        if i % 10 == 9:
            file.flush()


def test_a_full_disk_stops_the_file_with_a_clear_error_and_leaves_it_readable(
        tmp_path: Path) -> None:
    path = tmp_path / "run.mcap"
    file = McapFile(path, TYPES, compression="none", raw=FullDisk(path, 5000))
    with pytest.raises(StorageError) as stopped:
        fill(file, 1000)
    assert str(path) in str(stopped.value) and "the disk is full" in str(stopped.value)
    file.close()
    with open(path, "rb") as stream:
        summary = make_reader(stream).get_summary()
    assert summary is not None and summary.statistics is not None
    assert summary.chunk_indexes
    kept = [data for _topic, _log, _pub, data in raw_messages(path)]
    assert len(kept) == summary.statistics.message_count > 0
    assert len(kept) % 10 == 0  # whole flushed chunks, the cut one left out
    assert [String_data(data) for data in kept] == [f"{i:06d}" for i in range(len(kept))]


def String_data(data: bytes) -> str:  # noqa: N802
    return str(TYPES.deserialize(data, "std_msgs/msg/String").data)[:6]


def test_the_recorder_stops_on_a_full_disk_and_says_why(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    def on_small_disk(path: Path, types: MessageTypes, **options: Any) -> McapFile:
        return McapFile(path, types, raw=FullDisk(path, 200_000), **options)
    factory: Callable[..., McapFile] = on_small_disk
    monkeypatch.setattr(split, "McapFile", factory)
    monkeypatch.setattr(mcap_file, "FLUSH_INTERVAL", 0.05)  # chunks go out as they come
    path = tmp_path / "run.mcap"
    with Context(BusConfig.isolated()) as context:
        talker = Node("talker", context=context)
        publisher = talker.create_publisher("/log", String)
        assert wait_for(lambda: context.graph.count("/log", EntityKind.PUBLISHER) == 1, 10)
        recorder = Recorder(Node("recorder", context=context),
                            RecordingFiles(path, context.types, "none"), TopicSelection.of())
        assert "/log" in recorder.stats.topics
        for i in range(2000):
            publisher.publish(String(data=f"{i:06d}" + "y" * 300))
            if recorder.failure is not None:
                break
            time.sleep(0.002)
        assert wait_for(lambda: recorder.failure is not None, 20)
        recorder.close()
    assert recorder.failure is not None
    assert str(path) in recorder.failure and "the disk is full" in recorder.failure
    kept = raw_messages(path)
    assert 0 < len(kept) < 2000
    assert [String_data(data) for _t, _l, _p, data in kept] == [
        f"{i:06d}" for i in range(len(kept))]


def test_when_even_the_summary_finds_no_room_the_last_chunks_make_room_for_it(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    path = tmp_path / "run.mcap"
    file = McapFile(path, TYPES, compression="none", raw=FullDisk(path, 20_000))
    with pytest.raises(StorageError):
        fill(file, 1000)
    refusals = [2]
    real_complete = completion.complete

    def no_room_twice(*args: Any) -> int:
        if refusals[0]:
            refusals[0] -= 1
            raise OSError(errno.ENOSPC, "No space left on device")
        return real_complete(*args)
    monkeypatch.setattr(mcap_file, "complete", no_room_twice)
    file.close()
    assert refusals == [0]
    with open(path, "rb") as stream:
        summary = make_reader(stream).get_summary()
    assert summary is not None and summary.statistics is not None
    kept = raw_messages(path)
    assert len(kept) == summary.statistics.message_count == 10 * len(summary.chunk_indexes)
    assert [String_data(data) for _t, _l, _p, data in kept] == [
        f"{i:06d}" for i in range(len(kept))]
    assert summary.statistics.message_end_time == 10**18 + len(kept) - 1
