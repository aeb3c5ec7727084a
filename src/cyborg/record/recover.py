"""``cyborg record --recover CUT -o FIXED``: a readable, indexed copy of a cut recording.

A recording whose recorder was killed (``kill -9``, power loss, a crash) has no summary and
may end in a record cut short. :func:`recover` scans it up to its last whole record
(:mod:`cyborg.record.scan`: every complete chunk is kept, with every message in it, and
nothing after the cut is guessed at), copies that part byte for byte — the messages stay
compressed as they were — and appends the message index of the last chunk where it was cut,
the summary and the footer (:mod:`cyborg.record.completion`). Readers then open and seek the
copy like any finished recording.

Input that is no recording is refused with :class:`~cyborg.record.scan.NotRecoverableError`,
whose message names the file and what is wrong: empty, a ROS 1 bag or an SQLite database
named ``.mcap``, a text file, or a file cut before its header ended.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import BinaryIO

from cyborg.record.completion import complete, keep_until
from cyborg.record.scan import NotRecoverableError, Scan, scan

_COPY_BLOCK = 1 << 20


@dataclass(frozen=True)
class Recovery:
    """What :func:`recover` kept and what it had to leave."""

    source: Path
    target: Path
    messages: int
    topics: int
    start_ns: int
    end_ns: int
    kept_bytes: int
    """Bytes of the source copied (its whole records)."""
    lost_bytes: int
    """Bytes of the source after its last whole record (or its old summary)."""
    stopped: str
    """Why the scan stopped early, or empty when the source's data section was whole."""

    def describe(self) -> str:
        """One paragraph for the terminal: what was recovered, and what was not."""
        span = (self.end_ns - self.start_ns) / 1e9 if self.messages else 0.0
        text = (f"{self.target}: {self.messages} messages on {self.topics} topics "
                f"({span:.1f} s) recovered from {self.source}")
        if self.stopped:
            text += (f"; the {self.lost_bytes} bytes from byte {self.kept_bytes} on were left "
                     f"out: {self.stopped}")
        return text


def recover(source: Path, target: Path) -> Recovery:
    """Writes ``target``, the readable and indexed part of ``source``; see the module.

    Raises NotRecoverableError (naming ``source``) for input that is no recording,
    FileExistsError if ``target`` exists, ValueError if both name one file.
    """
    if target.exists():
        if source.exists() and target.resolve() == source.resolve():
            raise ValueError(f"{target}: the recovered copy must go to another file than "
                             "the cut one")
        raise FileExistsError(f"{target} exists already; choose another name or remove it")
    if source.is_dir():
        raise NotRecoverableError(f"{source}: a folder, not an MCAP file (recover the .mcap "
                                  "files of a bag folder one by one)")
    if not source.is_file():
        raise NotRecoverableError(f"{source}: no such file")
    found = scan(source)
    end = keep_until(found)
    with open(source, "rb") as cut, open(target, "xb") as out:
        _copy(cut, out, end)
        complete(found, out, end)
    return Recovery(source, target, found.message_count, _topics(found), found.start_time,
                    found.end_time, end, found.size - end,
                    "" if found.finished else found.stopped)


def _copy(source: BinaryIO, target: BinaryIO, length: int) -> None:
    remaining = length
    while remaining:
        block = source.read(min(_COPY_BLOCK, remaining))
        if not block:
            raise NotRecoverableError(f"{source.name}: the file shrank while it was copied")
        target.write(block)
        remaining -= len(block)


def _topics(found: Scan) -> int:
    return len({found.channels[channel].topic for channel, count in found.message_counts.items()
                if count and channel in found.channels})


__all__ = ["NotRecoverableError", "Recovery", "recover"]
