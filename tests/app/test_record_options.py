"""``cyborg record``'s and the recorder component's bad input: clear errors naming the option."""

from __future__ import annotations

from pathlib import Path

import pytest

from cyborg.app.cli import main
from cyborg.app.launchables import starter_for
from cyborg.bus import BusConfig, Context
from cyborg.bus.component import LaunchError, NodeSpec


@pytest.mark.parametrize(("words", "message"), [
    (["--split-size", "big"], "--split-size 'big': expected a size such as 500MB or 1GiB"),
    (["--split-duration", "0"], "--split-duration '0': must be more than 0"),
    (["--exclude", ""], "--exclude: an empty pattern"),
    (["--duration", "-1"], "--duration must be more than 0 seconds"),
])
def test_bad_options_are_refused_before_joining_the_bus(
        words: list[str], message: str, tmp_path: Path,
        capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["record", "-o", str(tmp_path / "run.mcap"), *words]) == 1
    assert message in capsys.readouterr().err
    assert not (tmp_path / "run.mcap").exists()


@pytest.mark.parametrize(("parameters", "message"), [
    ({}, "launch.toml: node 3: output: name the MCAP file to write"),
    ({"output": "run.mcap", "split_size": "huge"}, "launch.toml: node 3: --split-size 'huge'"),
    ({"output": "run.mcap", "compression": "rar"}, "compression 'rar': expected one of"),
])
def test_the_recorder_component_refuses_a_spec_naming_where_it_was_written(
        parameters: dict[str, object], message: str, tmp_path: Path) -> None:
    spec = NodeSpec("recorder", "recorder", "/", dict(parameters), base=tmp_path,
                    where="launch.toml: node 3")
    with Context(BusConfig.isolated()) as context, pytest.raises(LaunchError) as refused:
        starter_for(spec)(context, spec)
    assert message in str(refused.value)


def test_the_recorder_component_records_into_the_launch_files_folder(tmp_path: Path) -> None:
    spec = NodeSpec("recorder", "recorder", "/cyborg", {"output": "run.mcap", "map": "m.map"},
                    base=tmp_path, where="launch.toml: node 1")
    with Context(BusConfig.isolated()) as context:
        running = starter_for(spec)(context, spec)
        assert str(tmp_path / "run.mcap") in running.describe()
        assert "/cyborg/recorder/pause" in running.describe()
        running.stop()
    assert (tmp_path / "run.mcap").stat().st_size > 0


def test_the_live_line_shows_messages_megabytes_rate_topics_and_pause(tmp_path: Path) -> None:
    import io

    from cyborg.app.record_commands import RecordLine
    from cyborg.bus import Node
    from cyborg.record.recorder import Recorder
    from cyborg.record.selection import TopicSelection
    from cyborg.record.split import RecordingFiles

    with Context(BusConfig.isolated()) as context:
        recorder = Recorder(Node("recorder", context=context),
                            RecordingFiles(tmp_path / "run.mcap", context.types),
                            TopicSelection.of())
        recorder.stats.messages, recorder.stats.bytes = 12345, 4_100_000
        recorder.stats.topics.update({"/a": 1, "/b": 2})
        recorder.stats.skipped["/odd"] = "unknown type their_msgs/msg/Odd"
        recorder.stats.dropped = 3
        stream = io.StringIO()
        line = RecordLine(recorder, stream)
        assert not line.live
        line.update()
        recorder.set_paused(True)
        paused = line.text()
        recorder.close()
        line.finish()
    first = stream.getvalue().splitlines()[0]
    assert first.startswith("recording  12,345 msgs  4.1 MB  ")
    assert "/s  2 topics  0:00" in first
    assert paused.startswith("PAUSED")
    assert "12,345 messages on 2 topics, 4.1 MB of messages, 3 dropped" in stream.getvalue()
    assert "not recorded: /odd (unknown type their_msgs/msg/Odd)" in stream.getvalue()


@pytest.mark.parametrize(("images", "compression"), [(False, "zstd"), (True, "")])
def test_a_recording_with_images_is_not_compressed_unless_asked(
        images: bool, compression: str, tmp_path: Path) -> None:
    from mcap.reader import make_reader

    from cyborg.bus import Node, new_message
    from cyborg.record.component import RunningRecorder
    from tests.bus.bus_peer import wait_for

    spec = NodeSpec("recorder", "recorder", "/", {"output": "run.mcap", "images": images},
                    base=tmp_path, where="launch.toml: node 1")
    with Context(BusConfig.isolated()) as context:
        camera = Node("camera", context=context)
        publisher = camera.create_publisher("/camera/image", "sensor_msgs/msg/Image")
        log = camera.create_publisher("/log", "std_msgs/msg/String")
        running = starter_for(spec)(context, spec)
        assert isinstance(running, RunningRecorder)
        stats = running.recorder.stats
        assert wait_for(lambda: "/log" in stats.topics, 10)
        publisher.publish(new_message(context.types, "sensor_msgs/msg/Image",
                                      {"height": 1, "width": 1, "encoding": "mono8",
                                       "step": 1}))
        log.publish(new_message(context.types, "std_msgs/msg/String", {"data": "x"}))
        assert wait_for(lambda: stats.messages == (2 if images else 1), 10)
        running.stop()
    with open(tmp_path / "run.mcap", "rb") as stream:
        summary = make_reader(stream).get_summary()
    assert summary is not None
    assert {index.compression for index in summary.chunk_indexes} == {compression}
