"""``--recover``: a file cut anywhere gives back every message of its complete chunks, and no
other; input that is no recording is refused with the file and the reason named."""

from __future__ import annotations

import sqlite3
from pathlib import Path

import pytest
from mcap.reader import make_reader

from cyborg.app.cli import main
from cyborg.bus import MessageTypes
from cyborg.bus.msgs.geometry_msgs.msg import Pose2D
from cyborg.bus.msgs.std_msgs.msg import String
from cyborg.record.mcap_file import McapFile
from cyborg.record.recover import NotRecoverableError, recover
from tests.record.bad_recordings import REFUSED, refused, sqlite_bag
from tests.record.readers import raw_messages, read_rosbags

TYPES = MessageTypes()
BASE = 1_700_000_000_000_000_000


def cdr(message: object, type_name: str) -> bytes:
    return bytes(TYPES.serialize(message, type_name))


def write_recording(path: Path, chunks: int = 12, compression: str = "zstd") -> None:
    """A recording of ``chunks`` small chunks (flushed by hand), with metadata between."""
    file = McapFile(path, TYPES, compression=compression)
    pose = file.channel("/pose", "geometry_msgs/msg/Pose2D", ["::,5:,:,:,,"])
    log = file.channel("/log", "std_msgs/msg/String", [])
    file.metadata("cyborg", {"map": "campus.map"})
    for chunk in range(chunks):
        for i in range(chunk % 3 + 1):
            t = BASE + 1_000_000_000 * chunk + i
            file.write(pose, t, t - 5, cdr(Pose2D(x=chunk, y=i, theta=0.5),
                                           "geometry_msgs/msg/Pose2D"))
            if i % 2 == 0:
                file.write(log, t + 1, t, cdr(String(data=f"chunk {chunk} #{i}"),
                                              "std_msgs/msg/String"))
        file.flush()
        if chunk == 5:
            file.metadata("cyborg.map", {"source": "other.map"})
    file.close()


def chunk_ends(path: Path) -> list[int]:
    with open(path, "rb") as stream:
        summary = make_reader(stream).get_summary()
    assert summary is not None
    return sorted(index.chunk_start_offset + index.chunk_length for index in summary.chunk_indexes)


@pytest.mark.parametrize("compression", ["zstd", "lz4", "none"])
def test_a_file_cut_anywhere_recovers_exactly_the_messages_of_its_complete_chunks(
        tmp_path: Path, compression: str) -> None:
    whole = tmp_path / "whole.mcap"
    write_recording(whole, compression=compression)
    data = whole.read_bytes()
    ends = chunk_ends(whole)
    messages = raw_messages(whole)
    per_chunk = [sum(1 for m in messages if (m[1] - BASE) // 1_000_000_000 == k)
                 for k in range(12)]
    header_end = 8 + 9 + int.from_bytes(data[9:17], "little")
    cuts = sorted({*range(0, len(data), 29), *(end + d for end in ends for d in (-1, 0, 1)),
                   len(data) - 1, len(data)})
    for cut in cuts:
        source, target = tmp_path / "cut.mcap", tmp_path / "fixed.mcap"
        source.write_bytes(data[:cut])
        target.unlink(missing_ok=True)
        if cut < header_end:
            with pytest.raises(NotRecoverableError, match="cut"):
                recover(source, target)
            continue
        recovery = recover(source, target)
        complete = sum(1 for end in ends if end <= cut)
        expected = messages[:sum(per_chunk[:complete])]
        assert raw_messages(target) == expected, f"cut at {cut}"
        assert recovery.messages == len(expected)
        with open(target, "rb") as stream:
            summary = make_reader(stream).get_summary()
        assert summary is not None and summary.statistics is not None, f"cut at {cut}"
        assert len(summary.chunk_indexes) == complete
        assert summary.statistics.message_count == len(expected)
        assert all(index.message_index_offsets for index in summary.chunk_indexes)


def test_a_recovered_file_opens_in_rosbags_with_its_messages(tmp_path: Path) -> None:
    whole = tmp_path / "whole.mcap"
    write_recording(whole)
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(whole.read_bytes()[:chunk_ends(whole)[6] + 40])
    recover(cut, tmp_path / "fixed.mcap")
    found = read_rosbags(tmp_path / "fixed.mcap")
    assert [m["x"] for m in found["/pose"]] == [float(k) for k in range(7)
                                                 for _ in range(k % 3 + 1)]
    assert found["/log"][0] == {"data": "chunk 0 #0"}


def test_zeros_after_a_power_loss_end_the_scan_like_a_cut(tmp_path: Path) -> None:
    whole = tmp_path / "whole.mcap"
    write_recording(whole)
    end = chunk_ends(whole)[3]
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(whole.read_bytes()[:end] + bytes(4096))
    recovery = recover(cut, tmp_path / "fixed.mcap")
    assert recovery.messages == len([m for m in raw_messages(whole)
                                     if m[1] < BASE + 4_000_000_000])
    assert "no valid record" in recovery.stopped


def ros1_bag(path: Path) -> None:
    path.write_bytes(b"#ROSBAG V2.0\n" + bytes(4083))


def sqlite_db(path: Path) -> None:
    with sqlite3.connect(path) as db:
        db.execute("create table topics (id integer)")


@pytest.mark.parametrize(("make", "reason"), [
    (lambda p: p.write_bytes(b""), "the file is empty"),
    (lambda p: p.write_text("hello, this is a text file\n"), "a text file"),
    (ros1_bag, "a ROS 1 bag"),
    (sqlite_db, "an SQLite database"),
    (lambda p: p.write_bytes(b"\x89MCAP0"), "cut within its first 8 bytes"),
    (lambda p: p.write_bytes(b"\x89MCAP0\r\n\x01\x20\x00"), "cut before the end of its header"),
    (lambda p: p.write_bytes(bytes(range(256)) * 4), "not an MCAP file"),
])
def test_input_that_is_no_recording_is_refused_naming_the_file_and_the_reason(
        tmp_path: Path, make: object, reason: str, capsys: pytest.CaptureFixture[str]) -> None:
    source = tmp_path / "input.mcap"
    make(source)  # type: ignore[operator]
    with pytest.raises(NotRecoverableError) as refused:
        recover(source, tmp_path / "out.mcap")
    assert str(source) in str(refused.value) and reason in str(refused.value)
    assert not (tmp_path / "out.mcap").exists()
    assert main(["record", "--recover", str(source), "-o", str(tmp_path / "out.mcap")]) == 1
    error = capsys.readouterr().err
    assert str(source) in error and reason in error


def test_recover_refuses_a_missing_file_an_existing_target_and_no_target(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    missing = tmp_path / "missing.mcap"
    assert main(["record", "--recover", str(missing), "-o", str(tmp_path / "o.mcap")]) == 1
    assert f"{missing}: no such file" in capsys.readouterr().err
    whole = tmp_path / "whole.mcap"
    write_recording(whole)
    assert main(["record", "--recover", str(whole), "-o", str(whole)]) == 1
    assert "another file" in capsys.readouterr().err
    assert main(["record", "--recover", str(whole)]) == 1
    assert "--recover needs --output" in capsys.readouterr().err
    assert main(["record", "--recover", str(whole), "-o", str(tmp_path / "ok.mcap")]) == 0
    assert "recovered from" in capsys.readouterr().out


def test_recovering_a_whole_file_rebuilds_the_indexes_and_statistics_the_writer_wrote(
        tmp_path: Path) -> None:
    whole, fixed = tmp_path / "whole.mcap", tmp_path / "fixed.mcap"
    write_recording(whole)
    recovery = recover(whole, fixed)
    assert recovery.stopped == ""
    with open(whole, "rb") as original, open(fixed, "rb") as rebuilt:
        written, recovered = make_reader(original), make_reader(rebuilt)
        first, second = written.get_summary(), recovered.get_summary()
        assert first is not None and second is not None
        assert second.chunk_indexes == first.chunk_indexes
        assert second.statistics == first.statistics
        assert second.channels == first.channels and second.schemas == first.schemas
        assert list(recovered.iter_metadata()) == list(written.iter_metadata())


@pytest.mark.parametrize("name", sorted(REFUSED))
def test_recover_refuses_what_play_and_report_refuse_in_one_line(
        tmp_path: Path, name: str, capsys: pytest.CaptureFixture[str]) -> None:
    source, said = refused(name, tmp_path)
    target = tmp_path / "fixed.mcap"
    assert main(["record", "--recover", str(source), "-o", str(target)]) == 1
    error = capsys.readouterr().err
    assert error.startswith(f"cyborg: error: {source}: ") and said in error
    assert error.count("\n") == 1 and not target.exists()


def test_recover_refuses_a_ros2_bag_folder_saying_to_recover_its_files_one_by_one(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    folder = sqlite_bag(tmp_path / "bag")
    assert main(["record", "--recover", str(folder), "-o", str(tmp_path / "fixed.mcap")]) == 1
    assert capsys.readouterr().err == (f"cyborg: error: {folder}: a folder, not an MCAP file "
                                       "(recover the .mcap files of a bag folder one by one)\n")
