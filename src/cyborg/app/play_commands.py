"""``cyborg play``: a recording published on the bus again, with its timing and ``/clock``.

    cyborg play run.mcap                          at the recorded pace, then stop
    cyborg play run.mcap --rate 2 --start 120     twice as fast, from two minutes in
    cyborg play run.mcap --loop --topics /cyborg/pose /cyborg/map_geometry
    cyborg play run.mcap --exclude '/cyborg/camera/*'
    cyborg play robot.bag                         a ROS 1 bag; a ROS 2 bag folder plays too

With ``--connect`` (or ``$CYBORG_CONNECT``) it joins that router; without, it hosts the bus's
router at ``--listen`` (this machine's default address), as ``cyborg up`` does, or joins the one
already there, so that it plays as pasted while a monitor joins it. Ctrl-C and
SIGTERM stop it, saying how far it played. On a terminal the space key pauses and resumes and
``s`` plays one message (pausing first); the player's services do the same from anywhere
(``/player/pause``, ``/player/step``, ``/player/seek``: :mod:`cyborg.interfaces.player`). A
live line on stderr shows the position, the length, the rate and whether it is paused.
docs/recording.md ("Replay") says what is played and how.
"""

from __future__ import annotations

import argparse
import signal
import sys
import time
from pathlib import Path
from typing import Any, TextIO

from cyborg.app.bus_options import bus_context, open_context
from cyborg.app.command_table import COMMANDS
from cyborg.app.errors import CommandError, interrupt
from cyborg.app.keypress import Keys
from cyborg.app.progress import LiveLine, duration
from cyborg.bus import Context, MessageTypes, Node
from cyborg.bus.config import CONNECT_ENV, DEFAULT_ROUTER, BusConfig
from cyborg.interfaces import player as contract
from cyborg.record.playback_source import Recording, RecordingError, open_recording
from cyborg.record.player import Player, topic_filter
from cyborg.record.recorded import skipped_line

POLL = 0.1
"""Seconds between two looks at the player: the live line's redraw, the end."""


def add_parser(commands: Any) -> None:
    """Adds ``cyborg play`` to the commands."""
    play = commands.add_parser(
        "play", help=COMMANDS["play"].help,
        description="Publish a recording on the bus with its original timing, its messages' "
                    "bytes as recorded, /clock from its time and its latched topics latched.")
    play.add_argument("recording", type=Path, metavar="FILE",
                      help="an MCAP file (cyborg record's or ros2 bag's), a ROS 1 .bag, or a "
                           "ROS 2 bag folder")
    play.add_argument("--rate", type=float, default=1.0,
                      help="speed: 2 plays twice as fast (default 1)")
    play.add_argument("--start", type=float, default=0.0, metavar="SECONDS",
                      help="start this many seconds into the recording (default 0)")
    play.add_argument("--loop", action="store_true", help="play again from the start, forever")
    play.add_argument("--topics", nargs="+", default=[], metavar="TOPIC",
                      help="play only these topics (default: all)")
    play.add_argument("--exclude", action="append", default=[], metavar="PATTERN",
                      help="leave out topics matching this glob, e.g. '/cyborg/camera/*' "
                           "(repeatable)")
    play.add_argument("--paused", action="store_true",
                      help="start paused (space or the pause service starts it)")
    play.add_argument("--namespace", default="/", metavar="NS",
                      help="namespace of the player's node and services (default /)")
    play.add_argument("--connect", action="append", default=[], metavar="ENDPOINT",
                      help=f"router to join (default ${CONNECT_ENV}; without either, be the "
                           "router at --listen or join the one there)")
    play.add_argument("--listen", default=DEFAULT_ROUTER, metavar="ENDPOINT",
                      help=f"be the bus's router there unless --connect or ${CONNECT_ENV} "
                           f"names one; if a router already runs there, join it (default "
                           f"{DEFAULT_ROUTER})")
    play.add_argument("--wait", type=float, default=0.5, metavar="S",
                      help="seconds to let subscribers find the player's topics before the "
                           "first message (default 0.5)")
    play.set_defaults(handler=play_command)


def play_command(args: argparse.Namespace) -> int:
    """``cyborg play``: plays until the end (or Ctrl-C; never ends with ``--loop``)."""
    if not args.rate > 0:
        raise CommandError(f"--rate {args.rate}: give a speed above 0")
    if args.wait < 0:
        raise CommandError(f"--wait {args.wait}: give 0 seconds or more")
    types = MessageTypes()
    try:
        recording = open_recording(args.recording, types)  # bad input is said before joining
    except RecordingError as exc:
        raise CommandError(str(exc)) from None
    try:
        _check(args, recording)
        context = _context(args, types)
        try:
            return _play(args, context, recording, sys.stderr)
        finally:
            context.close()
    finally:
        recording.close()


def _context(args: argparse.Namespace, types: MessageTypes) -> Context:
    """The bus: the router ``--connect`` or the environment names, else one hosted here.

    Hosted at ``--listen`` as ``cyborg up`` hosts it (or joined, when a router already runs
    there), saying which on stderr.
    """
    if args.connect or BusConfig.from_environment().connect != (DEFAULT_ROUTER,):
        return open_context(args, types)
    context, where = bus_context([], args.listen, types)
    print(f"cyborg play: bus {where}", file=sys.stderr, flush=True)
    if args.listen != DEFAULT_ROUTER and where.startswith("router"):
        print(f"  other shells  export {CONNECT_ENV}={args.listen}  (or --connect "
              f"{args.listen}): commands join another bus by default", file=sys.stderr,
              flush=True)
    return context


def _check(args: argparse.Namespace, recording: Recording) -> None:
    """Refuses a start outside the recording and topics it does not have, naming them."""
    if not 0 <= args.start <= recording.duration:
        raise CommandError(f"--start {args.start}: {args.recording} is "
                           f"{recording.duration:.1f} s long")
    unknown = sorted(set(args.topics) - set(recording.topics) - set(recording.skipped))
    if unknown:
        raise CommandError(f"--topics: {', '.join(unknown)} not in {args.recording}; it has "
                           f"{', '.join(sorted(recording.topics)) or 'no playable topics'}")


def _play(args: argparse.Namespace, context: Context, recording: Recording,
          stream: TextIO) -> int:
    accept = topic_filter(args.topics, args.exclude)
    for note in notes(args.recording, recording):
        print(note, file=stream)
    player = Player(Node(contract.NAME, args.namespace, context=context), recording,
                    rate=args.rate, start=args.start, loop=args.loop, paused=True,
                    accept=accept)
    keys = "space pauses, s steps, " if sys.stdin.isatty() else ""
    print(f"cyborg play: {args.recording}, {duration(recording.duration)}, "
          f"{len(player.topics)} topics; {keys}Ctrl-C stops", file=stream, flush=True)
    line = PlayLine(player, stream)
    previous = signal.signal(signal.SIGTERM, interrupt)
    try:
        time.sleep(args.wait)
        player.set_paused(args.paused)
        with Keys(sys.stdin, {" ": player.toggle_pause, "s": player.step}) as keys_read:
            while not player.finished:
                line.update()
                keys_read.wait(POLL)
    except KeyboardInterrupt:
        pass
    finally:
        signal.signal(signal.SIGTERM, previous)
        player.close()
        line.finish()
    for topic, why in sorted(player.stats.failed.items()):
        print(f"  not published: {topic} ({why})", file=stream)
    return 0


def notes(path: Path, recording: Recording) -> list[str]:
    """What a user is told before play starts, one line each: the file was cut, topics skipped.

    The first suggests ``--recover`` for an indexed copy; the second names the topics that are
    not played with their reasons (the first ten; the rest counted).
    """
    said: list[str] = []
    if recording.cut is not None:
        said.append(f"cyborg play: {path} was cut ({recording.cut}); playing the "
                    f"{duration(recording.duration)} before it (cyborg record --recover "
                    f"{path} -o FIXED.mcap writes an indexed copy)")
    if recording.skipped:
        said.append(f"cyborg play: not played, {skipped_line(recording.skipped)}")
    return said


class PlayLine(LiveLine):
    """``playing  0:42 / 3:10  x2.0  1,234 msgs`` (or ``PAUSED``) on ``stream``."""

    def __init__(self, player: Player, stream: TextIO) -> None:
        super().__init__(stream)
        self.player = player

    def text(self) -> str:
        """The line as it is now."""
        player = self.player
        state = "PAUSED " if player.paused else "playing"
        loops = f"  loop {player.stats.loops + 1}" if player.loop else ""
        return self.fitted(
            f"{state}  {duration(player.position)} / {duration(player.recording.duration)}"
            f"  x{player.rate:g}  {player.stats.messages:,} msgs{loops}")

    def finish(self) -> None:
        """Ends the line and says what was played."""
        self.clear()
        stats = self.player.stats
        print(f"played {stats.messages:,} messages on {len(stats.topics)} topics, up to "
              f"{duration(self.player.position)} of {duration(self.player.recording.duration)}",
              file=self.stream, flush=True)
