"""How closely ``cyborg play`` keeps a recording's timing: publish time against schedule.

    python3 -m benchmarks.replay                 # 10 s of a cyborg up-like mix at rate 1
    python3 -m benchmarks.replay --seconds 30 --rate 2
    python3 -m benchmarks.replay --markdown      # the results table as Markdown
    python3 -m benchmarks.replay --quick         # a smoke test: 2 s

A recording is written first (:class:`cyborg.record.mcap_file.McapFile`, as the recorder
writes): ``/clock`` is left out so the player makes its own; ``/cyborg/pose`` at 50 Hz,
``/cyborg/scan`` (a 360-ray ``sensor_msgs/LaserScan``) at 10 Hz, ``/cyborg/bt/status`` at
20 Hz and a latched 200 kB ``/cyborg/map_geometry``-sized string once, for ``--seconds``.

Then, in the same run:

* **player** — :class:`cyborg.record.player.Player` plays it into a subscriber of another bus
  session (linked over loopback, so every message is serialised and sent); for each message
  the lateness is the monotonic time it was handed to the bus less the time it was due
  (``t0 + (log_time - log_time_0) / rate``);
* **baseline: sleep loop** — a bare loop that sleeps (``time.sleep``) until each of the same
  instants and notes how late it woke, publishing nothing: what the operating system's timer
  gives on this machine under its current load, the floor of any player in Python.

Reported for each: messages, p50, p99 and the worst lateness in milliseconds. The goal (issue
22) is a p99 of at most 5 ms at rate 1.
"""

from __future__ import annotations

import argparse
import socket
import statistics
import tempfile
import time
from pathlib import Path

from benchmarks import benchmark_options
from cyborg.bus import BusConfig, Context, MessageTypes, Node, new_message
from cyborg.bus.msgs.geometry_msgs.msg import Pose2D
from cyborg.bus.msgs.std_msgs.msg import String
from cyborg.interfaces import player as contract
from cyborg.record.mcap_file import McapFile
from cyborg.record.playback_source import Played, open_recording
from cyborg.record.player import Player


def write_recording(path: Path, seconds: float) -> int:
    """A recording of ``seconds`` of a cyborg up-like mix; the number of messages."""
    types = MessageTypes()
    scan = new_message(types, "sensor_msgs/msg/LaserScan",
                       {"ranges": [1.5] * 360, "angle_increment": 0.0174})
    payloads = {
        "/cyborg/pose": ("geometry_msgs/msg/Pose2D", 50,
                         bytes(types.serialize(Pose2D(x=1.0, y=2.0, theta=0.5),
                                               "geometry_msgs/msg/Pose2D"))),
        "/cyborg/scan": ("sensor_msgs/msg/LaserScan", 10,
                         bytes(types.serialize(scan, "sensor_msgs/msg/LaserScan"))),
        "/cyborg/bt/status": ("std_msgs/msg/String", 20,
                              bytes(types.serialize(String(data="x" * 300),
                                                    "std_msgs/msg/String"))),
    }
    schedule: list[tuple[int, str]] = []
    start = 1_000_000_000_000
    for topic, (_type, hertz, _data) in payloads.items():
        schedule += [(start + int(i * 1e9 / hertz), topic) for i in range(int(seconds * hertz))]
    schedule.sort()
    recording = McapFile(path, types, compression="zstd")
    latched = "1:1:1,1:,:,:,,"  # rmw_zenoh's QoS string of a latched publisher
    channel = recording.channel("/cyborg/map_geometry", "std_msgs/msg/String", [latched])
    recording.write(channel, start, start, bytes(types.serialize(
        String(data="m" * 200_000), "std_msgs/msg/String")))
    for log_time, topic in schedule:
        type_name, _hertz, data = payloads[topic]
        recording.write(recording.channel(topic, type_name, []), log_time, log_time, data)
    recording.close()
    return len(schedule) + 1


def percentiles(lateness: list[float]) -> dict[str, float]:
    """p50, p99 and the worst of ``lateness`` (seconds), in milliseconds."""
    ordered = sorted(lateness)
    cuts = statistics.quantiles(ordered, n=100, method="inclusive")
    return {"messages": len(ordered), "p50": cuts[49] * 1e3, "p99": cuts[98] * 1e3,
            "max": ordered[-1] * 1e3}


def linked() -> tuple[Context, Context]:
    """Two bus sessions linked peer to peer over loopback: (listening, playing)."""
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        address = f"tcp/127.0.0.1:{probe.getsockname()[1]}"
    listening = Context(BusConfig(connect=(), listen=(address,)))
    return listening, Context(BusConfig(connect=(address,), listen=()))


def play(path: Path, rate: float) -> list[float]:
    """Plays ``path`` into another session's subscriber; each message's lateness (s)."""
    lateness: list[float] = []

    def published(_played: Played, due: float, sent: float) -> None:
        lateness.append(sent - due)

    listening, playing = linked()
    with listening, playing:
        received = [0]
        listener = Node("listener", context=listening)
        for topic in ("/cyborg/pose", "/cyborg/scan", "/cyborg/bt/status"):
            listener.create_raw_subscription(
                topic, {"/cyborg/pose": "geometry_msgs/msg/Pose2D",
                        "/cyborg/scan": "sensor_msgs/msg/LaserScan"}.get(
                    topic, "std_msgs/msg/String"),
                lambda _raw: received.__setitem__(0, received[0] + 1))
        recording = open_recording(path, playing.types)
        player = Player(Node(contract.NAME, context=playing), recording, rate=rate,
                        paused=True, on_published=published)
        time.sleep(1.0)  # the subscriptions are matched
        player.set_paused(False)
        player.wait_finished(recording.duration / rate + 60)
        player.close()
        recording.close()
    return lateness[1:]  # the latched map, sent while repositioning, is due at no instant


def sleep_loop(path: Path, rate: float) -> list[float]:
    """The baseline: sleeps until each message's instant; how late each wake-up was (s)."""
    recording = open_recording(path, MessageTypes())
    times = [played.log_time for played in recording.messages()][1:]
    recording.close()
    lateness = []
    wall = time.monotonic()
    for log_time in times:
        due = wall + (log_time - times[0]) / 1e9 / rate
        remaining = due - time.monotonic()
        if remaining > 0:
            time.sleep(remaining)
        lateness.append(time.monotonic() - due)
    return lateness


def parser() -> argparse.ArgumentParser:
    """The benchmark's options."""
    options = benchmark_options(__doc__, quick="--seconds 2")
    options.add_argument("--seconds", type=float, default=10.0,
                         help="seconds of recording (default 10)")
    options.add_argument("--rate", type=float, default=1.0, help="the pace (default 1)")
    return options


def main(argv: list[str] | None = None) -> None:
    """Writes the recording, measures the player and the baseline, prints the figures."""
    args = parser().parse_args(argv)
    if args.quick:
        args.seconds = 2.0
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "replay.mcap"
        count = write_recording(path, args.seconds)
        rows = {"player (cyborg play)": percentiles(play(path, args.rate)),
                "baseline: sleep loop": percentiles(sleep_loop(path, args.rate))}
    print(f"{count} messages, {args.seconds:g} s at rate {args.rate:g}")
    if args.markdown:
        print("| schedule | messages | p50 ms | p99 ms | worst ms |\n| --- | ---: | ---: | ---: "
              "| ---: |")
    for name, row in rows.items():
        if args.markdown:
            print(f"| {name} | {row['messages']:.0f} | {row['p50']:.3f} | {row['p99']:.3f} | "
                  f"{row['max']:.3f} |")
        else:
            print(f"{name:24s} {row['messages']:6.0f} msgs  p50 {row['p50']:.3f} ms  "
                  f"p99 {row['p99']:.3f} ms  worst {row['max']:.3f} ms")


if __name__ == "__main__":
    main()
