"""``cyborg record`` as a user runs it: Ctrl-C leaves a complete file, ``kill -9`` a cut one
that ``--recover`` makes whole again, losing no more than the last second or so."""

from __future__ import annotations

import signal
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
from mcap.reader import make_reader

from cyborg.bus import BusConfig, Context, Node, Qos
from cyborg.bus.msgs.std_msgs.msg import String
from cyborg.record.scan import scan
from tests.app.test_bus_cli import first_line
from tests.ports import free_port
from tests.record.readers import read_mcap

pytestmark = pytest.mark.heavy


class Talker:
    """This process as the bus's router, publishing a counter at about 100 Hz and a latched map."""

    def __init__(self) -> None:
        self.address = f"tcp/127.0.0.1:{free_port()}"
        self.context = Context(BusConfig.router([self.address]))
        node = Node("talker", context=self.context)
        node.create_publisher("/map", String, Qos.latched()).publish(String(data="campus"))
        self._counter = node.create_publisher("/count", String)
        self.sent: list[float] = []
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _run(self) -> None:
        while not self._stop.wait(0.01):
            self._counter.publish(String(data=str(len(self.sent))))
            self.sent.append(time.monotonic())

    def close(self) -> None:
        self._stop.set()
        self._thread.join(5)
        self.context.close()


@pytest.fixture
def talker() -> Iterator[Talker]:
    running = Talker()
    yield running
    running.close()


def start_recording(talker: Talker, path: Path) -> subprocess.Popen[str]:
    process = subprocess.Popen(
        [sys.executable, "-m", "cyborg", "record", "-o", str(path), "--connect", talker.address],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert "writing" in first_line(process.stderr, 30), "the recorder did not start"
    return process


def counted(path: Path) -> list[int]:
    return [int(message["data"]) for message in read_mcap(path).get("/count", [])]


def test_ctrl_c_leaves_a_complete_indexed_file(talker: Talker, tmp_path: Path) -> None:
    path = tmp_path / "run.mcap"
    recording = start_recording(talker, path)
    start = len(talker.sent)
    deadline = time.monotonic() + 30
    while len(talker.sent) < start + 150 and time.monotonic() < deadline:
        time.sleep(0.05)
    recording.send_signal(signal.SIGINT)
    _out, err = recording.communicate(timeout=30)
    assert recording.returncode == 0, err
    assert f"{path}:" in err and "messages on 2 topics" in err
    with open(path, "rb") as stream:
        summary = make_reader(stream).get_summary()
    assert summary is not None and summary.chunk_indexes and summary.statistics is not None
    numbers = counted(path)
    assert len(numbers) >= 100
    assert numbers == list(range(numbers[0], numbers[0] + len(numbers)))  # none missing
    assert read_mcap(path)["/map"] == [{"data": "campus"}]


def test_after_kill_9_recover_gives_back_all_but_the_last_second(talker: Talker,
                                                                  tmp_path: Path) -> None:
    path, fixed = tmp_path / "run.mcap", tmp_path / "fixed.mcap"
    recording = start_recording(talker, path)
    time.sleep(6.0)
    killed_at = time.monotonic()
    recording.kill()
    recording.wait(30)
    # chunks go out at least every second; the rest of the margin is for a loaded machine
    published_before = sum(1 for sent in talker.sent if sent < killed_at - 4.0)
    assert not scan(path).finished  # cut: no Data End, no summary
    result = subprocess.run([sys.executable, "-m", "cyborg", "record", "--recover", str(path),
                             "-o", str(fixed)], capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stderr
    assert "recovered from" in result.stdout
    numbers = counted(fixed)
    assert numbers == list(range(numbers[0], numbers[0] + len(numbers)))
    assert numbers[-1] + 1 >= published_before, (numbers[-1], published_before)
    assert read_mcap(fixed)["/map"] == [{"data": "campus"}]


def test_cyborg_up_record_records_the_run_with_its_map_and_tree(tmp_path: Path) -> None:
    path = tmp_path / "up.mcap"
    result = subprocess.run(
        [sys.executable, "-m", "cyborg", "up", "--no-detector", "--no-monitor", "--record",
         str(path), "--duration", "6", "--listen", f"tcp/127.0.0.1:{free_port()}"],
        capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    assert f"recorder     {path}" in result.stdout
    with open(path, "rb") as stream:
        reader = make_reader(stream)
        summary = reader.get_summary()
        metadata = {item.name: item.metadata for item in reader.iter_metadata()}
    assert summary is not None and summary.statistics is not None
    counts = {summary.channels[channel].topic: count
              for channel, count in summary.statistics.channel_message_counts.items()}
    for topic in ("/cyborg/pose", "/cyborg/scan", "/cyborg/battery_status", "/cyborg/path",
                  "/cyborg/map_geometry", "/cyborg/bt/behavior_tree", "/cyborg/bt/status",
                  "/clock"):
        assert counts.get(topic, 0) > 0, topic
    assert metadata["cyborg"]["map"].endswith("campus.map")
    assert metadata["cyborg"]["tree"].endswith("campus.modes.toml")
    assert metadata["cyborg.map"]["source"] == "campus.map"
