"""``cyborg play`` as a user runs it: a recording published into another process's subscribers,
with its live line and closing summary; bad files refused before joining the bus."""

from __future__ import annotations

import io
import os
import pty
import subprocess
import sys
import termios
import time
from pathlib import Path

import pytest

from cyborg.app.cli import main
from cyborg.app.play_commands import PlayLine, notes
from cyborg.bus import BusConfig, Context, MessageTypes, Node
from cyborg.bus.config import CONNECT_ENV
from cyborg.bus.wire import EntityKind
from cyborg.record.playback_source import open_recording
from tests.bus.bus_peer import wait_for
from tests.ports import free_port
from tests.record.bad_recordings import (
    REFUSED,
    STRANGE_TOPICS,
    cut_in_its_middle,
    refused,
    small_recording,
    with_strange_schemas,
)
from tests.record.playing import CHATTER, Listener, record_run

STRING = "std_msgs/msg/String"


@pytest.mark.heavy
def test_cyborg_play_publishes_the_recording_to_another_process(tmp_path: Path) -> None:
    path = tmp_path / "run.mcap"
    record_run(path)
    recording = open_recording(path, MessageTypes())
    expected = [p.data for p in recording.messages() if p.topic == "/chatter"]
    recording.close()
    address = f"tcp/127.0.0.1:{free_port()}"
    with Context(BusConfig.router([address])) as bus:
        listener = Listener(Node("listener", context=bus))
        listener.listen("/chatter", STRING)
        listener.listen("/map", STRING, latched=True)
        result = subprocess.run(
            [sys.executable, "-m", "cyborg", "play", str(path), "--rate", "2", "--connect",
             address, "--wait", "1"], capture_output=True, text=True, timeout=120, check=False)
        assert result.returncode == 0, result.stderr
        assert wait_for(lambda: listener.data("/chatter") == expected, 20), result.stderr
        assert len(listener.data("/map")) == 1
    assert f"cyborg play: {path}" in result.stderr
    assert f"played {CHATTER + 1} messages on 2 topics" in result.stderr


@pytest.mark.heavy
def test_cyborg_play_with_no_router_reachable_hosts_one_as_cyborg_up_does(
        tmp_path: Path) -> None:
    path = tmp_path / "run.mcap"
    record_run(path)
    address = f"tcp/127.0.0.1:{free_port()}"
    environment = {key: value for key, value in os.environ.items() if key != CONNECT_ENV}
    play = subprocess.Popen(
        [sys.executable, "-m", "cyborg", "play", str(path), "--listen", address, "--wait", "3"],
        stderr=subprocess.PIPE, stdin=subprocess.DEVNULL, text=True, env=environment)
    assert play.stderr is not None
    first = play.stderr.readline()
    assert first.strip() == f"cyborg play: bus router at {address}", first
    with Context(BusConfig.from_environment([address])) as bus:  # a monitor, as it joins
        listener = Listener(Node("listener", context=bus))
        listener.listen("/map", STRING, latched=True)
        assert wait_for(lambda: len(listener.data("/map")) == 1, 20)
    _, err = play.communicate(timeout=120)
    assert play.returncode == 0, first + err
    assert "no router reachable" not in err
    assert f"played {CHATTER + 1} messages on 2 topics" in err


@pytest.mark.parametrize("name", sorted(REFUSED))
def test_a_bad_file_is_refused_in_one_line_naming_it_before_joining_the_bus(
        tmp_path: Path, name: str, capsys: pytest.CaptureFixture[str]) -> None:
    path, said = refused(name, tmp_path)
    assert main(["play", str(path), "--connect", "tcp/127.0.0.1:9"]) == 1
    error = capsys.readouterr().err
    assert error.startswith(f"cyborg: error: {path}: ") and said in error
    assert error.count("\n") == 1


def test_before_play_a_cut_file_and_the_topics_not_played_are_said_in_a_line_each(
        tmp_path: Path) -> None:
    whole = small_recording(tmp_path / "whole.mcap")
    cut = open_recording(cut_in_its_middle(whole, tmp_path / "cut.mcap"), MessageTypes())
    strange = open_recording(with_strange_schemas(tmp_path / "strange.mcap"), MessageTypes())
    try:
        said = notes(tmp_path / "cut.mcap", cut)
        assert len(said) == 1 and "was cut (a record cut short" in said[0]
        assert f"cyborg record --recover {tmp_path / 'cut.mcap'}" in said[0]
        [line] = notes(tmp_path / "strange.mcap", strange)
        assert line.startswith(f"cyborg play: not played, {len(STRANGE_TOPICS)} topics: ")
        assert "\n" not in line
        for topic, word in STRANGE_TOPICS.items():
            assert f"{topic} (" in line and word in line
    finally:
        cut.close()
        strange.close()
    complete = open_recording(whole, MessageTypes())
    assert notes(whole, complete) == []
    complete.close()


def test_a_start_outside_the_recording_and_unknown_topics_are_refused_naming_them(
        tmp_path: Path) -> None:
    path = tmp_path / "run.mcap"
    record_run(path)
    for options, said in ((["--start", "500"], "--start 500.0: "),
                          (["--topics", "/chatter", "/nothing"], "--topics: /nothing not in")):
        result = subprocess.run(
            [sys.executable, "-m", "cyborg", "play", str(path), *options, "--connect",
             "tcp/127.0.0.1:9"], capture_output=True, text=True, timeout=120, check=False)
        assert result.returncode == 1
        assert f"cyborg: error: {said}" in result.stderr
        assert str(path) in result.stderr


def test_the_live_line_shows_position_length_rate_and_pause() -> None:
    class Stats:
        messages, loops = 1234, 1

    class Shown:
        paused, position, rate, loop, stats = False, 42.4, 2.0, True, Stats()
        recording = type("R", (), {"duration": 190.0})()

    line = PlayLine(Shown(), io.StringIO())  # type: ignore[arg-type]
    assert line.text() == "playing  0:42 / 3:10  x2  1,234 msgs  loop 2"
    Shown.paused = True
    assert line.text().startswith("PAUSED   0:42 / 3:10")


@pytest.mark.heavy
def test_on_a_terminal_s_steps_and_space_resumes_a_paused_player(tmp_path: Path) -> None:
    path = tmp_path / "run.mcap"
    record_run(path)
    address = f"tcp/127.0.0.1:{free_port()}"
    controller, terminal = pty.openpty()
    with Context(BusConfig.router([address])) as bus:
        listener = Listener(Node("listener", context=bus))
        listener.listen("/chatter", STRING)
        player = subprocess.Popen(
            [sys.executable, "-m", "cyborg", "play", str(path), "--paused", "--connect",
             address], stdin=terminal, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
            text=True)
        os.close(terminal)
        try:
            assert wait_for(lambda: bus.graph.count("/player/step", EntityKind.SERVICE_SERVER),
                            60)
            # keys typed before the player reads them are flushed: wait for its cbreak mode
            assert wait_for(lambda: not termios.tcgetattr(controller)[3] & termios.ICANON, 60)
            os.write(controller, b"s")  # the map, recorded first
            os.write(controller, b"s")  # the first message of /chatter
            assert wait_for(lambda: len(listener.data("/chatter")) == 1, 30)
            time.sleep(0.5)
            assert len(listener.data("/chatter")) == 1  # stepped, then paused
            os.write(controller, b" ")
            _out, err = player.communicate(timeout=60)
        finally:
            if player.poll() is None:
                player.kill()
            os.close(controller)
        assert player.returncode == 0, err
        assert wait_for(lambda: len(listener.data("/chatter")) == CHATTER, 20)
    assert "space pauses, s steps" in err
    assert f"played {CHATTER + 1} messages" in err
