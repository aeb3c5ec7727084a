"""Recording the camera's full stream: MB/s, frames dropped, the recorder against mcap alone.

    python3 -m benchmarks.recording_camera                     # 60 s each, three rounds
    python3 -m benchmarks.recording_camera --seconds 10 --rounds 1   # a shorter measure
    python3 -m benchmarks.recording_camera --quick     # a smoke test: 0.5 s, one round
    python3 -m benchmarks.recording_camera --markdown          # the rows for docs/benchmarks.md
    python3 -m benchmarks.recording_camera --chunks            # the writer alone, flat out:
                                                               # chunk sizes x compressions

The frame is the sample camera's (:mod:`cyborg.vision.samples`, the Motorcycle pair's left
image and depth) scaled to 1920x1080: a ``bgr8`` Image of 6.2 MB and a ``32FC1`` depth Image of
8.3 MB, 14.5 MB a frame, serialised once before anything is timed; at 30 Hz that is 435 MB/s.
Each round runs, one after the other in this process so that the machine's load weighs on
both alike:

(a) **the mcap writer alone**: ``mcap.writer.Writer`` with the recorder's chunk size and
    compression, writing each frame's two messages to a plain file when the frame is due;
(b) **the recorder's path**: a :class:`~cyborg.record.recorder.Recorder` on an isolated bus,
    each message handed to its subscription as the bus hands it a sample from another process
    (the payload copied out of the shared-memory slot and stamped), then the recorder's own
    path: the topic's queue, the writer thread, the file with its chunk flushed and synced
    every second.

After the rounds, (c) **end to end**: another process publishes the same bytes at 30 Hz with
raw publishers; the recorder here receives them over the bus (shared memory between
processes, as ``cyborg record --images`` beside ``cyborg up``). The goal (ratio >= 0.8, no
frame dropped wherever the writer alone keeps up) is (b)'s: (c) adds the bus's transport
between processes, the same for any subscriber, measured in benchmarks/bus_transport.py.

Reported per measure: MB/s of messages (from the first frame due until the file is closed),
frames dropped (the recorder's own counter, and frames sent less frames in the file; for the
writer alone, frames it began more than a second late: what the recorder's one-second queue
would have dropped), the recorder's queue high-water mark, and CPU as % of one core. Files go
to a temporary folder (``--folder``) and are deleted as soon as they are measured. The
process keeps large buffers in malloc's heap as ``cyborg record`` does
(:func:`cyborg.app.memory.keep_large_buffers`) unless ``--default-malloc``.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np
from mcap.reader import make_reader
from mcap.writer import Writer

from benchmarks import benchmark_options
from benchmarks.results_table import print_results
from cyborg.app.memory import keep_large_buffers, limit_malloc_arenas
from cyborg.bus import BusConfig, Context, MessageTypes, Node
from cyborg.bus.raw import RawSubscription
from cyborg.bus.wire import Attachment
from cyborg.interfaces.detector import DEFAULT_DEPTH_TOPIC, DEFAULT_IMAGE_TOPIC
from cyborg.record import layout
from cyborg.record.component import IMAGE_COMPRESSION
from cyborg.record.mcap_file import CHUNK_SIZE, COMPRESSIONS
from cyborg.record.recorder import IMAGE_QUEUE_DEPTH, NAME, Recorder
from cyborg.record.selection import TopicSelection
from cyborg.record.split import RecordingFiles
from cyborg.vision.image_messages import bgr_to_image, depth_to_image
from cyborg.vision.samples import motorcycle

WIDTH, HEIGHT, RATE = 1920, 1080, 30.0
IMAGE_TYPE = "sensor_msgs/msg/Image"
TOPICS = (DEFAULT_IMAGE_TOPIC, DEFAULT_DEPTH_TOPIC)
LATE = IMAGE_QUEUE_DEPTH / RATE
"""A frame begun this late would have been dropped by the recorder's queue."""
CHUNK_SIZES_MIB = (1, 4, 8, 16, 32)

Frame = tuple[bytes, bytes]


def camera_frame() -> Frame:
    """The sample camera's frame at 1080p: the bgr8 image's and the depth's CDR."""
    left, _right, depth = motorcycle()
    image = cv2.resize(left, (WIDTH, HEIGHT), interpolation=cv2.INTER_LINEAR)
    metres = cv2.resize(np.nan_to_num(depth), (WIDTH, HEIGHT), interpolation=cv2.INTER_NEAREST)
    types = MessageTypes()
    return (bytes(types.serialize(bgr_to_image(image, 0, "camera"), IMAGE_TYPE)),
            bytes(types.serialize(depth_to_image(metres, 0, "camera"), IMAGE_TYPE)))


def schedule(seconds: float, start: float) -> Iterator[tuple[int, float]]:
    """(frame index, when it is due) at :data:`RATE` from ``start``, sleeping until each."""
    for index in range(int(seconds * RATE)):
        due = start + index / RATE
        ahead = due - time.perf_counter()
        if ahead > 0:
            time.sleep(ahead)
        yield index, due


@dataclass
class Phase:
    """What one measure did."""

    megabytes: float
    wall: float
    cpu: float
    sent: int
    dropped: int = 0
    """Frames not written: the recorder's count (the writer alone: frames begun too late)."""
    missing: int = 0
    """Frames sent less frames in the file."""
    backlog_peak: int = 0
    file_ratio: float = 1.0
    """The file's size against the messages' (compression)."""

    @property
    def mb_per_s(self) -> float:
        """Megabytes of messages written per wall-clock second."""
        return self.megabytes / self.wall

    @property
    def core(self) -> float:
        """CPU seconds per wall second, as % of one core."""
        return self.cpu / self.wall * 100


def frames_in(path: Path) -> int:
    """Whole frames in a recording: the fewest messages of any channel, from its summary."""
    with open(path, "rb") as stream:
        summary = make_reader(stream).get_summary()
    if summary is None or summary.statistics is None:
        raise RuntimeError(f"{path}: no summary")
    counts = summary.statistics.channel_message_counts
    return min((counts.get(channel, 0) for channel in summary.channels), default=0)


def writer_alone(frame: Frame, seconds: float, compression: str, chunk_size: int,
                 path: Path, *, paced: bool = True) -> Phase:
    """(a): mcap's writer alone writes the frames to a plain file, paced or flat out."""
    types = MessageTypes()
    cpu = time.process_time()
    start = time.perf_counter()
    late = sent = 0
    with open(path, "wb") as stream:
        writer = Writer(stream, chunk_size=chunk_size, compression=COMPRESSIONS[compression])
        writer.start(profile=layout.PROFILE, library="benchmark")
        schema = writer.register_schema(IMAGE_TYPE, layout.SCHEMA_ENCODING,
                                        layout.schema_text(types, IMAGE_TYPE))
        channels = [writer.register_channel(topic, layout.MESSAGE_ENCODING, schema)
                    for topic in TOPICS]
        frames = (schedule(seconds, start) if paced
                  else ((index, start) for index in range(int(seconds * RATE))))
        for _index, due in frames:
            late += paced and time.perf_counter() - due > LATE
            now = time.time_ns()
            for channel, data in zip(channels, frame, strict=True):
                writer.add_message(channel, now, data, now)
            sent += 1
        writer.finish()
    wall, cpu = time.perf_counter() - start, time.process_time() - cpu
    missing = sent - frames_in(path)
    megabytes = sent * sum(map(len, frame)) / 1e6
    ratio = path.stat().st_size / 1e6 / megabytes
    path.unlink()
    return Phase(megabytes, wall, cpu, sent, late, missing, file_ratio=ratio)


def arrive(subscription: RawSubscription, data: bytes, info: Attachment) -> None:
    """What the bus does with a sample from another process once it leased its slot."""
    subscription._admit(subscription._decode(memoryview(data)), info)


def wait_until(predicate: Callable[[], object], timeout: float) -> bool:
    """Polls ``predicate()`` until true or ``timeout`` seconds pass."""
    deadline = time.monotonic() + timeout
    while not predicate() and time.monotonic() < deadline:
        time.sleep(0.01)
    return bool(predicate())


def recorder_path(frame: Frame, seconds: float, compression: str, path: Path) -> Phase:
    """(b): the recorder's subscriptions, queue, writer thread and file, fed at 30 Hz."""
    with Context(BusConfig.isolated()) as context:
        camera = Node("camera", context=context)
        for topic in TOPICS:  # in the graph, for the recorder to find
            camera.create_raw_publisher(topic, IMAGE_TYPE)
        recorder = Recorder(Node(NAME, context=context),
                            RecordingFiles(path, context.types, compression),
                            TopicSelection.of(TOPICS))
        subscriptions = [recorder.subscriptions[topic] for topic in TOPICS]
        gids = [bytes([index + 1] * 16) for index in range(len(TOPICS))]
        stats = recorder.stats
        cpu = time.process_time()
        start = time.perf_counter()
        sent = 0
        for index, _due in schedule(seconds, start):
            for subscription, data, gid in zip(subscriptions, frame, gids, strict=True):
                arrive(subscription, data, Attachment(index + 1, time.time_ns(), gid))
            sent += 1
        wait_until(lambda: stats.messages + stats.dropped >= sent * len(TOPICS), 60)
        recorder.close()
        wall, cpu = time.perf_counter() - start, time.process_time() - cpu
    missing = sent - frames_in(path)
    path.unlink()
    return Phase(stats.bytes / 1e6, wall, cpu, sent, stats.dropped // len(TOPICS), missing,
                 recorder.backlog_peak)


def end_to_end(seconds: float, compression: str, path: Path) -> Phase:
    """(c): another process publishes the frames; the recorder here gets them over the bus."""
    import socket
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        endpoint = f"tcp/127.0.0.1:{probe.getsockname()[1]}"
    with Context(BusConfig.router([endpoint])) as context:
        camera = subprocess.Popen([sys.executable, "-m", "benchmarks.recording_camera",
                                   "--publish", endpoint, "--seconds", str(seconds)],
                                  stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
        assert camera.stdin is not None and camera.stdout is not None
        try:
            if camera.stdout.readline().strip() != "ready":
                raise RuntimeError("the publishing process did not start")
            recorder = Recorder(Node(NAME, context=context),
                                RecordingFiles(path, context.types, compression),
                                TopicSelection.of(TOPICS))
            stats = recorder.stats
            if not wait_until(lambda: set(TOPICS) <= stats.topics.keys(), 30):
                raise RuntimeError("the recorder did not find the camera's topics")
            cpu = time.process_time()
            start = time.perf_counter()
            camera.stdin.write("go\n")
            camera.stdin.flush()
            sent = int(camera.stdout.readline().split()[1])
            wait_until(lambda: stats.messages + stats.dropped >= sent * len(TOPICS), 10)
            recorder.close()
            wall, cpu = time.perf_counter() - start, time.process_time() - cpu
        finally:
            camera.stdin.close()
            camera.wait(30)
    missing = sent - frames_in(path)
    path.unlink()
    return Phase(stats.bytes / 1e6, wall, cpu, sent, stats.dropped // len(TOPICS), missing,
                 recorder.backlog_peak)


def publish(endpoint: str, seconds: float) -> None:
    """The other process of (c): publishes the frames at 30 Hz once told ``go``."""
    frame = camera_frame()
    with Context(BusConfig(connect=(endpoint,))) as context:
        node = Node("camera", context=context)
        publishers = [node.create_raw_publisher(topic, IMAGE_TYPE) for topic in TOPICS]
        print("ready", flush=True)
        if sys.stdin.readline().strip() != "go":
            return
        sent = 0
        for _index, _due in schedule(seconds, time.perf_counter()):
            for publisher, data in zip(publishers, frame, strict=True):
                publisher.publish_raw(data)
            sent += 1
        print(f"sent {sent}", flush=True)
        sys.stdin.read()


# ---------------------------------------------------------------------- reports
def spread(values: list[float], digits: int = 0) -> str:
    """``median (min-max)`` of the rounds, or the one value."""
    if len(values) == 1:
        return f"{values[0]:.{digits}f}"
    return (f"{statistics.median(values):.{digits}f} ({min(values):.{digits}f}-"
            f"{max(values):.{digits}f})")


def describe(phases: list[Phase], *, recorder: bool) -> str:
    """MB/s, frames dropped and missing, queue peak, CPU of some rounds of one measure."""
    dropped = sum(phase.dropped for phase in phases)
    missing = sum(phase.missing for phase in phases)
    text = (f"{spread([p.mb_per_s for p in phases])} MB/s, "
            f"{spread([p.core for p in phases])} % core, ")
    if recorder:
        peak = max(phase.backlog_peak for phase in phases)
        return text + (f"{dropped} dropped, {missing} missing in file, queue peak "
                       f"{peak}/{IMAGE_QUEUE_DEPTH}")
    return text + f"{dropped} begun > {LATE:g} s late"


def stream_report(frame: Frame, args: argparse.Namespace, folder: Path) -> None:
    """(a) and (b) interleaved for ``--rounds``, then (c); the results table."""
    alone: list[Phase] = []
    ours: list[Phase] = []
    for _round in range(args.rounds):
        alone.append(writer_alone(frame, args.seconds, args.compression, CHUNK_SIZE,
                                  folder / "writer_alone.mcap"))
        ours.append(recorder_path(frame, args.seconds, args.compression,
                                  folder / "recorder.mcap"))
    remote = [] if args.no_end_to_end else [end_to_end(args.seconds, args.compression,
                                                       folder / "end_to_end.mcap")]
    ratios = [b.mb_per_s / a.mb_per_s for a, b in zip(alone, ours, strict=True)]
    offered = sum(map(len, frame)) / 1e6
    # no frame may be dropped in a round where the writer alone kept up
    drops_allowed = all(b.dropped == 0 for a, b in zip(alone, ours, strict=True)
                        if a.dropped == 0)
    meets = statistics.median(ratios) >= 0.8 and drops_allowed
    rows = [(f"camera stream offered ({args.compression}, {CHUNK_SIZE // 2**20} MiB chunks)",
             f"{offered * RATE:.0f} MB/s: {offered:.1f} MB x {RATE:g} Hz, {args.seconds:g} s",
             "", f"{args.rounds} round(s), (a) and (b) interleaved"),
            ("(a) mcap writer alone", describe(alone, recorder=False), "1", "baseline"),
            ("(b) recorder: subscription, queue, writer thread, file",
             describe(ours, recorder=True), spread(ratios, 2),
             f">= 0.8, 0 dropped where (a) keeps up: {'meets' if meets else 'MISSES'}")]
    if remote:
        rows.append(("(c) end to end: publisher in another process, over the bus",
                     describe(remote, recorder=True),
                     f"{remote[0].mb_per_s / statistics.median(p.mb_per_s for p in alone):.2f}",
                     "reported (adds the transport between processes)"))
    print_results(f"Recording the camera's full stream ({time.strftime('%Y-%m-%d')})", rows,
                  markdown=args.markdown, widths=(58, 70, 16))


def chunks_report(frame: Frame, args: argparse.Namespace, folder: Path) -> None:
    """The writer alone flat out, for each compression and chunk size; median of rounds.

    MB per CPU second is the figure to compare on a loaded machine: MB/s falls with the share
    of a core the process gets.
    """
    rows = []
    offered = RATE * sum(map(len, frame)) / 1e6
    for compression in [args.compression] if args.compression else COMPRESSIONS:
        for mib in CHUNK_SIZES_MIB:
            phases = [writer_alone(frame, args.seconds, compression, mib * 2**20,
                                   folder / "chunks.mcap", paced=False)
                      for _round in range(args.rounds)]
            size = f"{compression}, {mib} MiB chunks"
            rows.append((size, f"{spread([p.mb_per_s for p in phases])} MB/s, "
                               f"{spread([p.megabytes / p.cpu for p in phases])} MB per CPU s, "
                               f"file {phases[0].file_ratio:.2f}x",
                         spread([p.mb_per_s / offered for p in phases], 2),
                         "ratio: of the camera's 435 MB/s"))
    print_results("The mcap writer alone, flat out, by compression and chunk size", rows,
                  markdown=args.markdown, widths=(24, 62, 16))


def parser() -> argparse.ArgumentParser:
    """The benchmark's options."""
    options = benchmark_options(__doc__, quick="--seconds 0.5 --rounds 1")
    options.add_argument("--seconds", type=float, default=60.0,
                         help="seconds of camera stream per measure (default 60)")
    options.add_argument("--rounds", type=int, default=3,
                         help="rounds of (a) and (b), interleaved (default 3)")
    options.add_argument("--compression", choices=sorted(COMPRESSIONS), default=None,
                         help=f"the recording's compression (default {IMAGE_COMPRESSION}, as "
                              "cyborg record --images; with --chunks: each)")
    options.add_argument("--chunks", action="store_true",
                         help="instead: the writer alone flat out, each compression and chunk size")
    options.add_argument("--no-end-to-end", action="store_true", help="leave out (c)")
    options.add_argument("--default-malloc", action="store_true",
                         help="leave glibc's malloc thresholds as they are")
    options.add_argument("--folder", type=Path, default=None,
                         help="where the files go (default: a temporary folder)")
    options.add_argument("--publish", default=None, help=argparse.SUPPRESS)
    return options


def main(argv: list[str] | None = None) -> None:
    args = parser().parse_args(argv)
    if args.quick:
        args.seconds, args.rounds = 0.5, 1
    limit_malloc_arenas()  # as `cyborg` does on start (cyborg.app.memory)
    if not args.default_malloc:
        keep_large_buffers()  # as `cyborg record` does
    if args.publish is not None:
        publish(args.publish, args.seconds)
        return
    frame = camera_frame()
    with tempfile.TemporaryDirectory(dir=args.folder) as folder:
        free = os.statvfs(folder)
        print(f"files in {folder} ({free.f_bavail * free.f_frsize / 1e9:.0f} GB free)",
              file=sys.stderr)
        if args.chunks:
            chunks_report(frame, args, Path(folder))
        else:
            args.compression = args.compression or IMAGE_COMPRESSION
            stream_report(frame, args, Path(folder))


if __name__ == "__main__":
    main()
