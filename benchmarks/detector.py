"""The detector end to end on 1080p frames with depth, against the 2018 approach, in one run.

    python3 -m benchmarks.detector             # full run, about 100 s
    python3 -m benchmarks.detector --quick     # smoke test: 1 short round, a few s
    python3 -m benchmarks.detector --markdown  # the tables as Markdown
    python3 -m benchmarks.detector --threads 1 # onnxruntime / OpenCV threads (default 2)

Frames (:mod:`benchmarks.detector_frames`): four photos from scikit-image tiled into a
1920x1080 BGR image (YOLOX-Nano finds 5 objects at confidence 0.5), with a float32 depth map
in metres with NaN, +inf, -inf and 0 holes; four variants are cycled, so consecutive frames are
different memory.

Measured in one run, on this machine:

* **ours, two processes** (:mod:`benchmarks.detector_ours`): a camera process publishes each
  frame on the bus as two ``sensor_msgs/Image`` (``bgr8`` + ``32FC1``, CameraNode's topics and
  encodings); a detector process runs the real :class:`~cyborg.vision.DetectorNode`
  (``DetectionPipeline``, onnxruntime, YOLOX-Nano 416, ``--threads``) and publishes
  ``Predictions`` and ``Detection2DArray``; the camera process receives the
  ``Detection2DArray``, which gives the latency. Run with **one frame in flight** (the next
  frame is sent when the last one's detections are back: clean per-stage times and latency)
  and **streaming** (two frames in flight, so one is always waiting when the detector finishes
  the other: the throughput, i.e. frames per second when the camera offers frames as fast as the
  detector takes them, none dropped). The camera sends as soon as the window allows: a
  streaming run starts with two frames published back to back.
* **ours, one process**: the same camera and detector nodes on one bus context, as
  ``cyborg up`` runs them (in-process delivery: the frame is handed over, not copied, and the
  detector's callback runs on the detector node's own thread, not the camera's). One frame in
  flight and streaming.
* **drawn or not**: the node draws (and publishes) the annotated image only while someone
  subscribes to ``detection_image``. By default a viewer in the detector's process does; the
  "nothing drawn" configurations (streaming, and one process) run without it.
* **2018 approach** (:mod:`benchmarks.detector_2018`): OpenCV DNN on the same ONNX file,
  stretch-resize, the per-row Python loop without NMS, the mean depth over the whole box,
  OpenCV's ``rectangle`` and ``putText`` on a copy of the frame, and the frame pickled down a
  ``multiprocessing`` Pipe. One frame in flight and streaming.
* **our pipeline alone**: :class:`~cyborg.vision.DetectionPipeline` on the same frames, no bus:
  frame in, detections with distances (and, drawn, the annotated image) out.
* **bare inference**: the onnxruntime session alone on a prepared tensor, same threads (and
  OpenCV DNN's ``forward`` alone, for the 2018 side).

Stages: transport (header stamp taken just before the camera publishes → both messages in the
detector's callback), message → frame (numpy views of the messages, frame checks),
preprocess, inference, postprocess (decode, NMS), distance, drawing, publish (building and
publishing the output messages). Throughput: frames answered per second. Configurations run
round-robin, several rounds; FPS is the median over rounds, a round's FPS being frames (or,
for bare inference, calls) per second of the round; it is also given over the rounds whose
inference ran at full speed (see :data:`FULL_SPEED`), and the FPS goal, which is about two
cores, is judged on that. Overhead = time per frame / bare inference - 1. The pipeline's
overhead is measured in pairs: one frame through the pipeline, then one bare inference on the
pipeline's own session, so that both halves of a pair see the same state of the machine. The
figure is the median over the pairs, over all of them and over those at full speed; the goal
is judged on the larger. The ratio of the table's medians is printed beside it. CPU used by
other processes is measured per round and reported.

Goals: >= 60 FPS end to end with onnxruntime on 2 cores; the pipeline's overhead (our pipeline
alone, drawn or not) <= 20 % over bare inference. The end-to-end configurations' overhead, which
adds the bus and the node, is reported beside it.
"""

from __future__ import annotations

import argparse
import math
import os
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from benchmarks import SHARED, benchmark_options
from benchmarks.detector_2018 import Approach2018
from benchmarks.detector_frames import STAGES, THRESHOLD, Run, make_frames, quantiles
from benchmarks.detector_ours import (
    BareInference,
    OursInProcess,
    OursTwoProcesses,
    PipelineAlone,
    detector_peer,
)

MODEL = SHARED / "models" / "yolox_nano.onnx"
GOAL_FPS, GOAL_OVERHEAD = 60.0, 0.20


# ---------------------------------------------------------------------- driver
CONFIGURATIONS = {
    "bare": "bare inference, onnxruntime",
    "bare_2018": "bare inference, OpenCV DNN (2018 side)",
    "pipeline": "our pipeline alone, drawn",
    "pipeline_plain": "our pipeline alone, nothing drawn",
    "streaming": "ours, 2 processes, streaming",
    "streaming_plain": "ours, 2 processes, streaming, nothing drawn",
    "lockstep": "ours, 2 processes, 1 frame in flight",
    "in_process": "ours, 1 process, 1 frame in flight",
    "in_process_streaming": "ours, 1 process, streaming",
    "in_process_plain": "ours, 1 process, streaming, nothing drawn",
    "old_streaming": "2018, 2 processes, streaming",
    "old_lockstep": "2018, 2 processes, 1 frame in flight"}


class CpuMeter:
    """How much CPU processes other than ours took (Linux ``/proc``; NaN elsewhere)."""

    def __init__(self) -> None:
        self.pids: list[int] = [os.getpid()]
        self.cores = os.cpu_count() or 1
        self._start = self._sample()

    @staticmethod
    def _jiffies(pid: int) -> int:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
        return int(fields[11]) + int(fields[12])  # utime + stime, all threads

    def _sample(self) -> tuple[float, int, int] | None:
        try:
            numbers = [int(value) for value in Path("/proc/stat").read_text().split()[1:9]]
            busy = sum(numbers) - numbers[3] - numbers[4]  # minus idle and iowait
            ours = sum(self._jiffies(pid) for pid in self.pids)
        except (OSError, ValueError, IndexError):
            return None
        return time.monotonic(), busy, ours

    def restart(self) -> None:
        self._start = self._sample()

    def foreign(self) -> float:
        """Share of all cores used by other processes since the last ``restart``."""
        end = self._sample()
        if end is None or self._start is None:
            return math.nan
        ticks = os.sysconf("SC_CLK_TCK")
        seconds = end[0] - self._start[0]
        other = (end[1] - self._start[1]) - (end[2] - self._start[2])
        return max(0.0, other / ticks / (seconds * self.cores))


@dataclass
class Results:
    runs: dict[str, Run]
    threads: int
    rounds: int
    dropped: int
    seconds: float
    foreign: list[float]
    bus_drops: dict[str, int]


def measure(model: Path, threads: int, quick: bool) -> Results:
    """Every configuration once per round, round-robin, so drift touches all alike."""
    started = time.monotonic()
    frames = make_frames()
    rounds, scale = (1, 25) if quick else (5, 1)
    runs = {key: Run(name) for key, name in CONFIGURATIONS.items()}
    bare = BareInference(frames, model, threads)
    pipeline = PipelineAlone(frames, model, threads)
    in_process = OursInProcess(frames, model, threads)
    two = OursTwoProcesses(frames, model, threads)
    old = Approach2018(frames, model, threads)
    meter = CpuMeter()
    meter.pids += [two.peer.pid, old.peer.pid or 0]
    foreign = []
    try:
        warm_up = 5 if quick else 20
        in_process.run(warm_up, 1)  # warm-ups
        two.run(warm_up, 1)
        old.bare(min(warm_up, 5))
        old.run(3, 1)
        for _ in range(rounds):
            meter.restart()
            runs["bare"].add(bare.run(100 // scale))
            runs["bare_2018"].add(old.bare(40 // scale))
            runs["pipeline"].add(pipeline.paired(200 // scale, draw=True))
            runs["pipeline_plain"].add(pipeline.paired(200 // scale, draw=False))
            runs["in_process"].add(in_process.run(100 // scale, 1))
            runs["in_process_streaming"].add(in_process.run(200 // scale, 2))
            runs["in_process_plain"].add(in_process.run(200 // scale, 2, draw=False))
            runs["lockstep"].add(two.run(100 // scale, 1))
            runs["streaming"].add(two.run(250 // scale, 2))
            runs["streaming_plain"].add(two.run(250 // scale, 2, draw=False))
            runs["old_lockstep"].add(old.run(max(3, 15 // scale), 1))
            runs["old_streaming"].add(old.run(max(5, 30 // scale), 2))
            foreign.append(meter.foreign())
    finally:
        old.close()
        two.close()
        in_process.close()
    bus_drops = dict(two.bus_drops)
    for reason, count in in_process.context.dropped.items():
        bus_drops[reason] = bus_drops.get(reason, 0) + count
    return Results(runs, threads, rounds, in_process.dropped + two.dropped,
                   time.monotonic() - started, foreign, bus_drops)


# ---------------------------------------------------------------------- report
FULL_SPEED = 1.25
"""Inference ran at full speed (a pair, or a configuration's round) when it took at most this
times the fastest tenth of the run's bare inferences. This host now and then takes most of the
second core away for seconds at a time: inference, on two threads, then slows by up to 2x while
the single-threaded rest of the pipeline does not. That makes the overhead look smaller than it
is and the frame rates lower than two cores give; figures at full speed are the two cores'."""


def full_speed_limit(runs: dict[str, Run]) -> float:
    """Inference at full speed takes at most this many ms: :data:`FULL_SPEED` times the fastest
    tenth of the pipeline's paired bare inferences (a thousand or more, spread over the run)."""
    samples = runs["pipeline"].paired_bare + runs["pipeline_plain"].paired_bare
    return FULL_SPEED * float(np.percentile(samples, 10)) if samples else math.inf


def _full_speed(run: Run, limit: float) -> str:
    fps, count = run.fps_at_full_speed(limit)
    return f"{fps:.1f} ({count} of {len(run.fps_rounds)})" if count else \
        f"— (0 of {len(run.fps_rounds)})"


@dataclass(frozen=True)
class Overhead:
    """The pipeline's overhead over bare inference, from pairs: median and middle half."""

    median: float
    low: float
    high: float
    pairs: int

    @staticmethod
    def of(ratios: Sequence[float]) -> Overhead:
        if not ratios:
            return Overhead(math.nan, math.nan, math.nan, 0)
        low, median, high = np.percentile(ratios, [25, 50, 75])
        return Overhead(float(median), float(low), float(high), len(ratios))

    @staticmethod
    def at_full_speed(run: Run, limit: float) -> Overhead:
        """Over the pairs whose bare inference took at most ``limit`` ms."""
        return Overhead.of([ratio for ratio, bare in zip(run.paired, run.paired_bare,
                                                         strict=True) if bare <= limit])

    def __str__(self) -> str:
        return (f"{self.median * 100:.1f} % (median of {self.pairs} pairs, middle half "
                f"{self.low * 100:.1f} to {self.high * 100:.1f} %)")


def _cell(pair: tuple[float, float]) -> str:
    return "—" if math.isnan(pair[0]) else f"{pair[0]:.2f} / {pair[1]:.2f}"


def _table(header: Sequence[str], rows: Sequence[Sequence[str]], markdown: bool) -> None:
    if markdown:
        print("| " + " | ".join(header) + " |")
        print("| --- |" + " --: |" * (len(header) - 1))
        for row in rows:
            print("| " + " | ".join(row) + " |")
        return
    widths = [max(len(row[i]) for row in [header, *rows]) for i in range(len(header))]
    for row in [header, *rows]:
        print("  ".join(value.ljust(widths[i]) if i == 0 else value.rjust(widths[i])
                        for i, value in enumerate(row)))


def _goal(met: bool) -> str:
    return "met" if met else "NOT met"


def report(results: Results, markdown: bool) -> None:
    runs = results.runs
    bare = runs["bare"].per_frame_ms
    bare_2018 = runs["bare_2018"].per_frame_ms
    print(f"1920x1080 BGR + 32FC1 depth, YOLOX-Nano 416, {results.threads} inference "
          f"thread(s), confidence {THRESHOLD}, {os.cpu_count()} cores; {results.rounds} "
          f"rounds, {results.seconds:.0f} s\n")
    print("Per-stage times, ms per frame, median / p90:\n")
    keys = ("lockstep", "streaming", "in_process", "in_process_plain", "old_lockstep")
    header: tuple[str, ...] = (
        "stage", "ours, 2 processes", "ours, 2 processes, streaming (a)", "ours, 1 process",
        "ours, 1 process, streaming, nothing drawn (a)", "2018, 2 processes", "2018 / ours")
    rows = []
    for stage in STAGES:
        ours, old = runs["lockstep"].stage(stage)[0], runs["old_lockstep"].stage(stage)[0]
        ratio = f"{old / ours:.1f}x" if ours > 0 and not math.isnan(old) else ""
        rows.append((stage, *(_cell(runs[key].stage(stage)) for key in keys), ratio))
    sums = [sum(value for stage in STAGES if not math.isnan(value := runs[key].stage(stage)[0]))
            for key in keys]
    rows.append(("sum of the medians", *(f"{value:.2f}" for value in sums),
                 f"{sums[-1] / sums[0]:.1f}x"))
    rows.append(("detections per frame",
                 *(f"{quantiles(runs[key].detections)[0]:.0f}" for key in keys), ""))
    _table(header, rows, markdown)
    print("\n(a) two frames in flight: transport includes the wait in the detector's queue while "
          "the frame before is processed (in one process too: the frame is handed to the "
          "detector node's own thread and waits there). Other columns: one frame in flight. "
          "Nothing drawn: no subscriber to detection_image. 2018: message → frame is part of "
          "transport (unpickling).")

    limit = full_speed_limit(runs)
    print("\nThroughput and latency (FPS: median over rounds, lowest and highest in brackets; "
          "at full speed: median over the rounds whose inference ran at full speed):\n")
    header = ("configuration", "FPS", "FPS at full speed (rounds)", "ms per frame",
              "latency median / p90 ms", "x bare inference", "x 60 FPS goal")
    rows = [(CONFIGURATIONS["bare"], f"{1000 / bare:.1f}", _full_speed(runs["bare"], limit),
             f"{bare:.2f}", "", "1.00x", ""),
            (CONFIGURATIONS["bare_2018"], f"{1000 / bare_2018:.1f}", "", f"{bare_2018:.2f}", "",
             "1.00x", "")]
    for key in ("pipeline", "pipeline_plain", "streaming", "streaming_plain", "lockstep",
                "in_process", "in_process_streaming", "in_process_plain", "old_streaming",
                "old_lockstep"):
        run = runs[key]
        own_bare = bare_2018 if key.startswith("old") else bare
        spread = f" ({min(run.fps_rounds):.0f} to {max(run.fps_rounds):.0f})"
        rows.append((run.name, f"{run.fps:.1f}{spread}",
                     "" if key.startswith("old") else _full_speed(run, limit),
                     f"{run.per_frame_ms:.2f}", _cell(quantiles(run.latency)),
                     f"{run.per_frame_ms / own_bare:.2f}x", f"{run.fps / GOAL_FPS:.2f}x"))
    _table(header, rows, markdown)
    print("\nx bare inference: ms per frame / the bare inference of the same runtime "
          "(ours: onnxruntime; 2018: OpenCV DNN)\n")
    for key in ("pipeline", "pipeline_plain"):
        run = runs[key]
        every, full_speed = Overhead.of(run.paired), Overhead.at_full_speed(run, limit)
        overhead = max(every.median, full_speed.median)
        print(f"{run.name}: pipeline overhead over bare inference {every} of all pairs, "
              f"{full_speed} of the pairs at full speed (bare inference at most {limit:.2f} ms: "
              f"{FULL_SPEED:.2f}x the run's fastest tenth); from the table's medians "
              f"{(run.per_frame_ms / bare - 1) * 100:.0f} % "
              f"(goal <= {GOAL_OVERHEAD * 100:.0f} %: {_goal(overhead <= GOAL_OVERHEAD)})")
    for key in ("streaming", "streaming_plain", "in_process_streaming", "in_process_plain"):
        run = runs[key]
        overhead = run.per_frame_ms / bare - 1
        fps, count = run.fps_at_full_speed(limit)
        at_full_speed = (f"{fps:.1f} over the {count} at full speed (goal >= {GOAL_FPS:.0f} on "
                         f"two cores: {_goal(fps >= GOAL_FPS)})" if count else
                         "no round at full speed (goal on two cores: not measured; run again)")
        print(f"{run.name}: {run.fps:.1f} FPS end to end over all rounds, {at_full_speed}; "
              f"with the bus and the node, {overhead * 100:.0f} % over bare inference")
    old = runs["old_streaming"].fps
    latency = (quantiles(runs["old_lockstep"].latency)[0]
               / quantiles(runs["lockstep"].latency)[0])
    print(f"ours / 2018: {runs['streaming'].fps / old:.1f}x the frames per second (two "
          f"processes, streaming), {runs['in_process_streaming'].fps / old:.1f}x in one process; "
          f"{latency:.1f}x lower latency (two processes, one frame in flight)")
    lost = ", ".join(f"{run.lost} of {run.frames + run.lost} ({run.name})"
                     for run in runs.values() if run.lost)
    print(f"frames without an answer: {lost or 'none'}; dropped or failed by the detector "
          f"nodes: {results.dropped}; dropped by the bus: "
          + (", ".join(f"{count} ({reason})" for reason, count in results.bus_drops.items())
             or "none"))
    shares = ", ".join(f"{share * 100:.0f} %" for share in results.foreign)
    print(f"CPU taken by other processes, per round: {shares}"
          + (" — DISTURBED: figures are not trustworthy; run again on a quiet machine"
             if any(share > 0.05 for share in results.foreign) else ""))
    print("2018 side: the same ONNX model on OpenCV DNN (the 2018 Darknet YOLOv3 weights are "
          "not available, and OpenCV 5 removed the Darknet importer)")


def parser() -> argparse.ArgumentParser:
    """The benchmark's options."""
    options = benchmark_options(__doc__, quick="one round of a few frames each")
    options.add_argument("--threads", type=int, default=2,
                         help="onnxruntime and OpenCV DNN threads (default 2)")
    options.add_argument("--model", type=Path, default=MODEL,
                         help="a YOLOX-Nano ONNX file (default: $CYBORG_SHARED/models)")
    options.add_argument("--detector-peer", metavar="ENDPOINT", help=argparse.SUPPRESS)
    return options


def main(argv: list[str] | None = None) -> None:
    options = parser()
    args = options.parse_args(argv)
    if args.detector_peer:
        detector_peer(args.detector_peer, args.model, args.threads)
        return
    if not args.model.is_file():
        options.error(f"model {args.model} not found (set CYBORG_SHARED or give --model)")
    report(measure(args.model, args.threads, args.quick), args.markdown)


if __name__ == "__main__":
    main()
