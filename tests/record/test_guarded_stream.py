"""The file under a recording syncs to the disk beside the writer, never in its way."""

from __future__ import annotations

import os
import threading
from pathlib import Path

import pytest

from cyborg.record.guarded_stream import GuardedStream


def test_a_sync_runs_beside_the_writer_and_close_waits_for_it(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    started, release = threading.Event(), threading.Event()
    synced: list[int] = []

    def slow_disk(descriptor: int) -> None:
        started.set()
        release.wait(30)
        synced.append(descriptor)
    monkeypatch.setattr(os, "fsync", slow_disk)  # the guarded stream's sync calls os.fsync
    stream = GuardedStream(tmp_path / "run.mcap")
    stream.write(b"first chunk")
    stream.sync()
    assert started.wait(10)
    stream.write(b" and the next")  # the writer goes on while the disk catches up
    stream.sync()  # asked for while one runs: follows it
    assert stream.good == len(b"first chunk and the next")
    closing = threading.Thread(target=stream.close)
    closing.start()
    closing.join(0.2)
    assert closing.is_alive()  # not closed under a running sync
    release.set()
    closing.join(30)
    assert not closing.is_alive()
    assert len(synced) >= 1
    assert (tmp_path / "run.mcap").read_bytes() == b"first chunk and the next"
