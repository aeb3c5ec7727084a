"""``cyborg record``: the bus into an MCAP file, and ``--recover`` for a cut one.

    cyborg record -o run.mcap                       every topic but images and hidden ones
    cyborg record /cyborg/pose /cyborg/scan -o run.mcap
    cyborg record -o run.mcap --exclude '/cyborg/camera/*' --images --compression lz4
    cyborg record -o run.mcap --split-size 1GiB     a bag folder: run/run_0.mcap, ...
    cyborg record --recover cut.mcap -o fixed.mcap  a readable, indexed copy of a cut file

It joins the bus's router like the other bus commands (``--connect``, ``--wait``) and records
until Ctrl-C (or ``--duration``), which finishes the file with its summary. A live line on
stderr shows the messages, megabytes and rate; into a pipe or file a line comes every ten
seconds. The key ``p`` (on a terminal) and ``kill -USR1`` pause and resume it, as does its
service ``/recorder/pause`` (``std_srvs/srv/SetBool``). A full disk stops it with exit code 1
and a readable file. docs/recording.md says what a recording holds.
"""

from __future__ import annotations

import argparse
import os
import shlex
import signal
import sys
import time
from pathlib import Path
from typing import Any, TextIO

from cyborg.app.bus_options import open_context
from cyborg.app.command_table import COMMANDS
from cyborg.app.errors import CommandError, interrupt
from cyborg.app.keypress import Keys
from cyborg.app.memory import keep_large_buffers
from cyborg.app.progress import LiveLine, duration, size
from cyborg.bus import Node
from cyborg.bus.config import DEFAULT_ROUTER
from cyborg.record import component
from cyborg.record.mcap_file import COMPRESSIONS
from cyborg.record.recorder import NAME, Recorder
from cyborg.record.recover import NotRecoverableError, recover
from cyborg.record.selection import TopicSelection
from cyborg.record.split import RecordingFiles, SplitPolicy, parse_duration, parse_size

POLL = 0.1
"""Seconds between two looks at the recorder: the live line's redraw, a failure, the end."""


def add_parser(commands: Any) -> None:
    """Adds ``cyborg record`` to the commands."""
    record = commands.add_parser(
        "record", help=COMMANDS["record"].help,
        description="Record topics of the bus into an MCAP file in the rosbag2 layout, "
                    "readable by ros2 bag, Foxglove and rosbags.")
    record.add_argument("topics", nargs="*", metavar="TOPIC",
                        help="topics to record (default: all but images and hidden ones)")
    record.add_argument("-o", "--output", type=Path, default=None, metavar="FILE",
                        help="the MCAP file to write (default: cyborg_<date>_<time>.mcap)")
    record.add_argument("--exclude", action="append", default=[], metavar="PATTERN",
                        help="leave out topics matching this glob, e.g. '/cyborg/camera/*' "
                             "(repeatable)")
    record.add_argument("--images", action="store_true",
                        help="record image topics too when recording all topics")
    record.add_argument("--compression", choices=sorted(COMPRESSIONS),
                        default=None,
                        help=f"chunk compression (default {component.COMPRESSION}; "
                             f"{component.IMAGE_COMPRESSION} with --images)")
    record.add_argument("--split-size", default=None, metavar="SIZE",
                        help="start a new file past this size, e.g. 1GiB (a bag folder: "
                             "run/run_0.mcap, run/run_1.mcap, ..., run/metadata.yaml)")
    record.add_argument("--split-duration", default=None, metavar="DURATION",
                        help="start a new file after this long, e.g. 10m")
    record.add_argument("--duration", type=float, default=None, metavar="SECONDS",
                        help="stop after this many seconds")
    record.add_argument("--recover", type=Path, default=None, metavar="CUT",
                        help="instead of recording: write a readable, indexed copy of a cut "
                             "recording to --output")
    record.add_argument("--connect", action="append", default=[], metavar="ENDPOINT",
                        help=f"router to join (default $CYBORG_CONNECT or {DEFAULT_ROUTER})")
    record.add_argument("--wait", type=float, default=0.5, metavar="S",
                        help="seconds to wait for the graph to fill before starting "
                             "(default 0.5; later topics are picked up anyway)")
    record.set_defaults(handler=record_command)


def record_command(args: argparse.Namespace) -> int:
    """``cyborg record``: records until Ctrl-C; or ``--recover``."""
    if args.recover is not None:
        return recover_command(args)
    output: Path = args.output or Path(time.strftime("cyborg_%Y-%m-%d_%H-%M-%S.mcap"))
    try:
        selection = TopicSelection.of(args.topics, args.exclude, images=args.images)
        policy = SplitPolicy(parse_size(args.split_size) if args.split_size else None,
                             parse_duration(args.split_duration) if args.split_duration
                             else None)
        if args.duration is not None and args.duration <= 0:
            raise ValueError("--duration must be more than 0 seconds")
    except ValueError as exc:
        raise CommandError(str(exc)) from None
    keep_large_buffers()  # large messages (images, maps) without a page fault per 4 KiB
    context = open_context(args)
    try:
        try:
            compression = args.compression or component.default_compression(args.images)
            files = RecordingFiles(output, context.types, compression, policy)
        except (FileExistsError, OSError) as exc:
            raise CommandError(str(exc)) from None
        recorder = Recorder(Node(NAME, context=context), files, selection,
                            run={"command": shlex.join(["cyborg", *sys.argv[1:]])})
        return _follow(recorder, args.duration, sys.stderr)
    finally:
        context.close()


def _follow(recorder: Recorder, limit: float | None, stream: TextIO) -> int:
    """Shows the live line until Ctrl-C, SIGTERM, ``limit`` or a failure; then finishes."""
    line = RecordLine(recorder, stream)
    key = "p or " if sys.stdin.isatty() else ""
    print(f"cyborg record: writing {recorder.files.paths[0]}; Ctrl-C stops, "
          f"{key}kill -USR1 {os.getpid()} pauses and resumes", file=stream, flush=True)
    previous = {signum: signal.getsignal(signum) for signum in (signal.SIGTERM, signal.SIGUSR1)}
    signal.signal(signal.SIGTERM, interrupt)
    signal.signal(signal.SIGUSR1, lambda _signum, _frame: recorder.toggle_pause())
    started = time.monotonic()
    try:
        with Keys(sys.stdin, {"p": recorder.toggle_pause}) as keys:
            while recorder.failure is None:
                if limit is not None and time.monotonic() - started >= limit:
                    break
                line.update()
                keys.wait(POLL)
    except KeyboardInterrupt:
        pass
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)
        recorder.close()
        line.finish()
    if recorder.failure is not None:
        raise CommandError(recorder.failure)
    return 0



class RecordLine(LiveLine):
    """``recording  1,234 msgs  5.6 MB  120.3 kB/s  14 topics  0:42`` on ``stream``.

    ``PAUSED`` shows while the recording is paused.
    """

    def __init__(self, recorder: Recorder, stream: TextIO) -> None:
        super().__init__(stream)
        self.recorder = recorder
        self.started = time.monotonic()

    def text(self) -> str:
        """The line as it is now."""
        stats = self.recorder.stats
        elapsed = max(time.monotonic() - self.started, 1e-9)
        state = "PAUSED   " if self.recorder.paused else "recording"
        return self.fitted(f"{state}  {stats.messages:,} msgs  {size(stats.bytes)}  "
                           f"{size(stats.bytes / elapsed)}/s  {len(stats.topics)} topics  "
                           f"{duration(elapsed)}")

    def finish(self) -> None:
        """Ends the line and says what was recorded, and what was skipped."""
        self.clear()
        stats, recorder = self.recorder.stats, self.recorder
        files = ", ".join(str(path) for path in recorder.files.paths)
        if recorder.files.folder is not None:
            files = f"{recorder.files.folder} ({len(recorder.files.paths)} files)"
        dropped = f", {stats.dropped:,} dropped (the writer fell behind)" if stats.dropped else ""
        print(f"{files}: {stats.messages:,} messages on {len(stats.topics)} topics, "
              f"{size(stats.bytes)} of messages{dropped}", file=self.stream)
        for topic, why in sorted(stats.skipped.items()):
            print(f"  not recorded: {topic} ({why})", file=self.stream)
        self.stream.flush()


def recover_command(args: argparse.Namespace) -> int:
    """``cyborg record --recover CUT -o FIXED``."""
    if args.output is None:
        raise CommandError("--recover needs --output (-o): the file to write the recovered "
                           "copy to")
    try:
        recovery = recover(args.recover, args.output)
    except (NotRecoverableError, FileExistsError, ValueError, OSError) as exc:
        raise CommandError(str(exc)) from None
    print(recovery.describe())
    return 0
