"""``cyborg report``: one self-contained HTML page of a recorded run.

    cyborg report run.mcap                  writes run.html beside it
    cyborg report run.mcap -o /tmp/run.html

The page (:mod:`cyborg.report`) holds its own style, script and drawings, so it opens in any
browser from the file, with no server: per robot its tree with per-node counts and times, the
path driven on the map, the battery, the goals reached and failed, the detections per minute
and the warnings. A cut recording (after ``kill -9``) is reported as far as it is readable; a
file that is no recording is refused, naming it and what is wrong (exit status 1).
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from cyborg.app.command_table import COMMANDS
from cyborg.app.errors import CommandError
from cyborg.record.playback_source import RecordingError
from cyborg.record.recorded import skipped_line
from cyborg.report.build import write_report


def add_parser(commands: Any) -> None:
    """Adds ``cyborg report`` to the commands."""
    report = commands.add_parser(
        "report", help=COMMANDS["report"].help,
        description="Write one self-contained HTML page of an MCAP recording: tree, path on "
                    "the map, battery, goals, detections and warnings of each robot.")
    report.add_argument("recording", type=Path, metavar="FILE",
                        help="the MCAP recording (cyborg record, cyborg up --record)")
    report.add_argument("-o", "--output", type=Path, default=None, metavar="HTML",
                        help="the page to write (default: FILE with the suffix .html)")
    report.set_defaults(handler=report_command)


def report_command(args: argparse.Namespace) -> int:
    """``cyborg report FILE [-o HTML]``."""
    source: Path = args.recording
    output: Path = args.output or source.with_suffix(".html")
    if output.resolve() == source.resolve():
        raise CommandError(f"{output}: the report would overwrite the recording; name another "
                           "file with -o")
    try:
        recording = write_report(source, output)
    except RecordingError as exc:
        raise CommandError(str(exc)) from None
    except OSError as exc:
        raise CommandError(f"{output}: cannot be written: {exc.strerror or exc}") from None
    cut = f"; the file was cut ({recording.cut})" if recording.cut else ""
    print(f"report of {source} ({recording.message_count:,} messages on "
          f"{len(recording.topics)} topics) written to {output}{cut}")
    if recording.skipped:
        print(f"cyborg report: not read, {skipped_line(recording.skipped)}")
    return 0
