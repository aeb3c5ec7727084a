"""What recording costs with each compression: CPU per MB, MB/s and file size.

    python3 -m benchmarks.recording                   # records `cyborg up` 20 s, then measures
    python3 -m benchmarks.recording --sample run.mcap # measures on a recording made before
    python3 -m benchmarks.recording --markdown        # the results table as Markdown
    python3 -m benchmarks.recording --quick           # a smoke test: 3 s recorded, 2 MB written

The messages are the default topics of ``cyborg up`` (no camera images: a recording of all
topics leaves them out), taken from a real run: ``cyborg up --no-detector --no-monitor --record``
for ``--seconds`` (20) unless ``--sample`` names a recording. Each compression then writes the
same messages, repeated to at least ``--megabytes`` (64) MB of CDR, into a fresh file through
:class:`cyborg.record.mcap_file.McapFile`, closing a chunk every second's worth of messages as
the recorder does. Reported per compression: the process CPU seconds per MB of messages, the MB
of messages written per wall-clock second, the file size against the messages', and the share
of one core that recording ``cyborg up``'s own data rate takes at that CPU cost.
"""

from __future__ import annotations

import argparse
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from mcap.reader import make_reader

from benchmarks import benchmark_options
from cyborg.bus import MessageTypes
from cyborg.record.mcap_file import COMPRESSIONS, McapFile

Sample = list[tuple[str, str, int, bytes]]
"""(topic, type, log time, CDR) of each message, in order."""


def record_sample(seconds: float, folder: Path) -> Path:
    """Records ``cyborg up`` for ``seconds`` on a bus of its own (a free loopback port)."""
    path = folder / "sample.mcap"
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        endpoint = f"tcp/127.0.0.1:{probe.getsockname()[1]}"
    subprocess.run([sys.executable, "-m", "cyborg", "up", "--no-detector", "--no-monitor",
                    "--listen", endpoint, "--record", str(path), "--duration", str(seconds)],
                   check=True, stdout=subprocess.DEVNULL, timeout=seconds + 120)
    return path


def read_sample(path: Path) -> tuple[Sample, float]:
    """The messages of a recording and its duration in seconds."""
    with open(path, "rb") as stream:
        reader = make_reader(stream)
        sample = [(channel.topic, schema.name if schema else "", message.log_time,
                   message.data)
                  for schema, channel, message in reader.iter_messages(log_time_order=True)]
    span = (sample[-1][2] - sample[0][2]) / 1e9 if len(sample) > 1 else 1.0
    return sample, span


def measure(sample: Sample, span: float, compression: str, megabytes: float,
            folder: Path) -> dict[str, float]:
    types = MessageTypes()
    per_pass = sum(len(data) for *_rest, data in sample)
    passes = max(1, int(megabytes * 1e6 / per_pass) + 1)
    path = folder / f"{compression}.mcap"
    path.unlink(missing_ok=True)
    cpu, wall = time.process_time(), time.perf_counter()
    file = McapFile(path, types, compression=compression)
    channels = {topic: file.channel(topic, type_name, []) for topic, type_name, *_ in sample}
    per_second = max(1, int(len(sample) / span))
    written = 0
    for repeat in range(passes):
        offset = int(repeat * span * 1e9)
        for index, (topic, _type, log_time, data) in enumerate(sample):
            file.write(channels[topic], log_time + offset, log_time + offset, data)
            written += len(data)
            if index % per_second == per_second - 1:
                file.flush()
    file.close()
    cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
    megabytes_written = written / 1e6
    live_rate = per_pass / 1e6 / span
    return {"cpu_s_per_mb": cpu / megabytes_written, "mb_per_s": megabytes_written / wall,
            "size_ratio": path.stat().st_size / written, "live_mb_per_s": live_rate,
            "core_share_live": cpu / megabytes_written * live_rate, "megabytes": megabytes_written}


def parser() -> argparse.ArgumentParser:
    """The benchmark's options."""
    options = benchmark_options(__doc__, quick="--seconds 3 --megabytes 2")
    options.add_argument("--sample", type=Path, default=None, help="a recording to measure on")
    options.add_argument("--seconds", type=float, default=20.0,
                         help="how long to record cyborg up for the sample (default 20)")
    options.add_argument("--megabytes", type=float, default=64.0,
                         help="MB of messages each compression writes (default 64)")
    return options


def main(argv: list[str] | None = None) -> None:
    args = parser().parse_args(argv)
    if args.quick:
        args.seconds, args.megabytes = 3.0, 2.0
    with tempfile.TemporaryDirectory() as folder:
        path = args.sample or record_sample(args.seconds, Path(folder))
        sample, span = read_sample(path)
        results = {name: measure(sample, span, name, args.megabytes, Path(folder))
                   for name in COMPRESSIONS}
    topics = len({topic for topic, *_ in sample})
    print(f"sample: {len(sample)} messages on {topics} topics over {span:.1f} s, "
          f"{next(iter(results.values()))['live_mb_per_s'] * 1000:.1f} kB/s of CDR")
    if args.markdown:
        print("| compression | CPU s per MB | MB/s | file / messages | one core at cyborg "
              "up's rate |")
        print("| --- | ---: | ---: | ---: | ---: |")
    for name, result in results.items():
        if args.markdown:
            print(f"| {name} | {result['cpu_s_per_mb']:.4f} | {result['mb_per_s']:.0f} | "
                  f"{result['size_ratio']:.2f} | {result['core_share_live'] * 100:.2f} % |")
        else:
            print(f"{name:5}  {result['cpu_s_per_mb']:.4f} CPU s/MB  "
                  f"{result['mb_per_s']:6.0f} MB/s  size {result['size_ratio']:.2f}x  "
                  f"{result['core_share_live'] * 100:.2f} % of a core at cyborg up's rate")


if __name__ == "__main__":
    main()
