"""``cyborg detect``: find objects, and how far away they are, in recorded or live images.

::

    cyborg detect photo.jpg                              # the objects in one image
    cyborg detect sample:motorcycle                      # a stereo sample with depth
    cyborg detect ride.mp4 --out ride_detected.mp4       # annotated video, with a progress bar
    cyborg detect left.png,right.png --focal 700 --baseline 0.12   # depth from a stereo pair
    cyborg detect recording.bag --depth-topic /zed/depth/depth_registered --json -
    cyborg detect bus:/cyborg/camera/left/image_raw --depth-topic /cyborg/camera/depth/...
    cyborg detect models list | fetch yolox_nano [--dir DIR] [--url URL]

The model is ``--model`` (a path, or a name looked up in ``$CYBORG_MODELS``,
``$CYBORG_SHARED/models`` and ``~/.cache/cyborg/models``; default ``yolox_nano``).
"""

from __future__ import annotations

import argparse
import json
import sys
from collections import Counter
from pathlib import Path
from typing import Any, TextIO

from cyborg.app.command_table import COMMANDS
from cyborg.app.detect_output import FrameWriter
from cyborg.app.errors import CommandError
from cyborg.app.progress import ProgressBar
from cyborg.vision import (
    DetectionPipeline,
    Detector,
    FrameSource,
    Result,
    SourceOptions,
    StereoCalibration,
    StereoDepth,
    VisionError,
    open_source,
)
from cyborg.vision.annotate import caption
from cyborg.vision.detector import DEFAULT_BACKEND, DEFAULT_CONFIDENCE, DEFAULT_IOU
from cyborg.vision.file_sources import DEFAULT_RATE
from cyborg.vision.models import CATALOGUE, DEFAULT_MODEL, cache_dir, fetch, find_model
from cyborg.vision.pipeline import STAGES


def add_parser(commands: Any) -> None:
    """Adds ``cyborg detect`` (and ``cyborg detect models``) to the commands."""
    detect = commands.add_parser(
        "detect", help=COMMANDS["detect"].help,
        description="Run the object detector on a source and report labelled boxes with "
                    "their distance. SOURCE: an image, a folder, a video, LEFT,RIGHT, a ROS "
                    "bag, camera:N, sample:motorcycle or bus:TOPIC. `cyborg detect models "
                    "list|fetch NAME` lists and downloads known models.",
        formatter_class=argparse.RawDescriptionHelpFormatter)
    detect.add_argument("source", help="what to read (or 'models')")
    detect.add_argument("models_args", nargs="*", help=argparse.SUPPRESS)
    model = detect.add_argument_group("model")
    model.add_argument("--model", default=DEFAULT_MODEL,
                       help=f"model file or name (default {DEFAULT_MODEL})")
    model.add_argument("--family", default=None,
                       help="yolox, yolov5, yolov7, yolov8, yolo11, yolov10, darknet "
                            "(default: from the model)")
    model.add_argument("--backend", choices=("onnxruntime", "opencv"), default=DEFAULT_BACKEND,
                       help=f"the network's runtime (default {DEFAULT_BACKEND})")
    model.add_argument("--weights", type=Path, default=None, help="Darknet .weights file")
    model.add_argument("--labels", type=Path, default=None,
                       help="class names, one per line (default: COCO)")
    model.add_argument("--threads", type=int, default=0, help="inference threads (0: auto)")
    model.add_argument("--input-size", type=int, default=None,
                       help="input size for models with a dynamic one")
    model.add_argument("--confidence", type=float, default=DEFAULT_CONFIDENCE,
                       help=f"threshold ({DEFAULT_CONFIDENCE:g})")
    model.add_argument("--iou", type=float, default=DEFAULT_IOU,
                       help=f"NMS overlap threshold ({DEFAULT_IOU:g})")
    model.add_argument("--classes", default="", help="labels to keep, comma-separated")
    source = detect.add_argument_group("source")
    source.add_argument("--right", type=Path, default=None, help="right image of a pair")
    source.add_argument("--depth", type=Path, default=None,
                        help="depth map of an image (.npy metres, 16-bit PNG millimetres)")
    source.add_argument("--side-by-side", action="store_true",
                        help="frames hold left and right side by side (ZED)")
    source.add_argument("--rate", type=float, default=DEFAULT_RATE,
                        help=f"frames per second of image folders (stamps; default "
                             f"{DEFAULT_RATE:g})")
    source.add_argument("--image-topic", default=None, help="bag topic of the image")
    source.add_argument("--depth-topic", default=None, help="bag or bus topic of depth")
    source.add_argument("--right-topic", default=None, help="bag or bus topic of the right "
                                                            "image")
    source.add_argument("--connect", action="append", default=[], metavar="ENDPOINT",
                        help="router to join for bus: sources")
    stereo = detect.add_argument_group("depth from a rectified stereo pair")
    stereo.add_argument("--focal", type=float, default=None, help="focal length, pixels")
    stereo.add_argument("--baseline", type=float, default=None, help="baseline, metres")
    stereo.add_argument("--doffs", type=float, default=0.0,
                        help="principal points' x difference, pixels (default 0)")
    stereo.add_argument("--max-disparity", type=int, default=64,
                        help="disparity search range, a multiple of 16 (default 64)")
    out = detect.add_argument_group("output")
    show = out.add_mutually_exclusive_group()
    show.add_argument("--show", action="store_true", help="show the annotated frames")
    show.add_argument("--out", type=Path, default=None,
                      help="annotated video (.mp4, .avi), image (.png, .jpg) or folder")
    out.add_argument("--json", default=None, metavar="FILE",
                     help="one JSON line of detections per frame ('-': standard output)")
    out.add_argument("--limit", type=int, default=None, help="stop after N frames")
    out.add_argument("--duration", type=float, default=None,
                     help="bus sources: stop after this many seconds without a frame")
    models = detect.add_argument_group("models fetch")
    models.add_argument("--dir", type=Path, default=None, help="where to put the model "
                        "(default ~/.cache/cyborg/models)")
    models.add_argument("--url", default=None, help="download from this address instead")
    detect.set_defaults(handler=detect_command)


def detect_command(args: argparse.Namespace) -> int:
    """``cyborg detect``: the objects in a source, or ``models list|fetch``."""
    try:
        if args.source == "models":
            return models_command(args)
        if args.models_args:
            raise CommandError(f"one SOURCE only, not {args.source} "
                               f"{' '.join(args.models_args)}; a stereo pair is LEFT,RIGHT")
        return _detect(args)
    except VisionError as exc:
        raise CommandError(str(exc)) from exc


def build_pipeline(args: argparse.Namespace) -> DetectionPipeline:
    """The detector the options ask for, with depth from a stereo pair where one is given."""
    classes = frozenset(name.strip() for name in args.classes.split(",") if name.strip())
    if not 0 <= args.confidence <= 1 or not 0 <= args.iou <= 1:
        raise CommandError("--confidence and --iou are between 0 and 1")
    detector = Detector.open(args.model, backend=args.backend, family=args.family,
                             weights=args.weights, labels=args.labels, threads=args.threads,
                             input_size=args.input_size, confidence=args.confidence,
                             iou=args.iou, classes=classes)
    unknown = sorted(classes - set(detector.labels))
    if unknown:
        raise CommandError(f"--classes: unknown labels {', '.join(unknown)}")
    stereo = None
    if (args.focal is None) != (args.baseline is None):
        raise CommandError("depth from a stereo pair needs both --focal and --baseline")
    if args.focal is not None:
        stereo = StereoDepth(StereoCalibration(args.focal, args.baseline, args.doffs),
                             max_disparity=args.max_disparity)
    elif args.source.startswith("sample:"):
        from cyborg.vision.samples import MOTORCYCLE_CALIBRATION
        stereo = StereoDepth(MOTORCYCLE_CALIBRATION)
    return DetectionPipeline(detector, stereo=stereo)


def _open(args: argparse.Namespace) -> tuple[FrameSource, Any]:
    if args.source.startswith("bus:"):
        from cyborg.app.detect_bus import open_bus_source
        return open_bus_source(args)
    options = SourceOptions(right=args.right, depth=args.depth, side_by_side=args.side_by_side,
                            rate=args.rate, image_topic=args.image_topic,
                            depth_topic=args.depth_topic, right_topic=args.right_topic)
    return open_source(args.source, options), None


def _detect(args: argparse.Namespace) -> int:
    pipeline = build_pipeline(args)
    source, bus = _open(args)
    writer = FrameWriter(args.out, show=args.show, rate=args.rate)
    json_out: TextIO | None = None
    if args.json is not None:
        json_out = sys.stdout if args.json == "-" else open(args.json, "w", encoding="utf-8")  # noqa: SIM115
    total = source.length if args.limit is None or source.length is None \
        else min(source.length, args.limit)
    progress = ProgressBar(sys.stderr, total)
    labels: Counter[str] = Counter()
    stage_sums = dict.fromkeys(STAGES, 0.0)
    frames = 0
    last: Result | None = None
    try:
        for frame in source:
            last = pipeline.process(frame, draw=writer.wanted)
            frames += 1
            labels.update(detection.label for detection in last.detections)
            for stage in STAGES:
                stage_sums[stage] += last.times[stage]
            if json_out is not None:
                json_out.write(json.dumps(frame_record(last)) + "\n")
            writer.write(last)
            if total != 1:
                progress.update(frames, f"{len(last.detections)} objects")
            if args.limit is not None and frames >= args.limit:
                break
    finally:
        source.close()
        writer.close()
        if json_out is not None and json_out is not sys.stdout:
            json_out.close()
        if bus is not None:
            bus.close()
    if total != 1 and frames:
        progress.finish()
    if frames == 0:
        raise CommandError(f"{args.source}: no frames" + (
            f" ({source.dropped} dropped without their partner)" if source.dropped else ""))
    if frames == 1 and last is not None and json_out is not sys.stdout:
        for detection in last.detections:
            x1, y1, x2, y2 = (round(value) for value in detection.box)
            print(f"{caption(detection):40s} box {x1},{y1} {x2},{y2}")
        if not last.detections:
            print("no objects found")
    report = sys.stderr if json_out is sys.stdout else sys.stdout
    summary(report, frames, labels, stage_sums, source.dropped, writer)
    return 0


def frame_record(result: Result) -> dict[str, Any]:
    """One frame's detections as JSON-ready data (distance ``null`` when unknown)."""
    return {"index": result.frame.index, "stamp_ns": result.frame.stamp_ns,
            "detections": [{"label": d.label, "confidence": round(d.confidence, 4),
                            "distance": None if d.distance != d.distance
                            else round(d.distance, 4),
                            "box": [round(value, 1) for value in d.box]}
                           for d in result.detections]}


def summary(stream: TextIO, frames: int, labels: Counter[str], stage_sums: dict[str, float],
            dropped: int, writer: FrameWriter) -> None:
    """Prints what was found in how many frames, the time per stage, and where frames went."""
    found = ", ".join(f"{label} {count}" for label, count in labels.most_common()) or "nothing"
    per_frame = sum(stage_sums.values()) / frames
    stages = "  ".join(f"{stage} {stage_sums[stage] / frames * 1e3:.1f}" for stage in STAGES)
    print(f"{frames} frame{'s' if frames != 1 else ''}: {found}", file=stream)
    print(f"per frame {per_frame * 1e3:.1f} ms ({1 / per_frame if per_frame else 0:.0f} FPS):"
          f" {stages} ms", file=stream)
    if dropped:
        print(f"{dropped} frames dropped without their partner (image or depth)", file=stream)
    if writer.path is not None:
        print(f"annotated frames written to {writer.path}", file=stream)


def models_command(args: argparse.Namespace) -> int:
    """``cyborg detect models``: lists the known models, or fetches one."""
    action, *names = args.models_args or ["list"]
    if action == "list":
        for model in CATALOGUE.values():
            try:
                where = str(find_model(model.name))
            except VisionError:
                where = "not downloaded"
            print(f"{model.name:12s} {model.family:6s} {model.licence:10s} "
                  f"{model.description}\n{'':12s} {where}")
        return 0
    if action != "fetch" or len(names) != 1:
        raise CommandError("usage: cyborg detect models list | fetch NAME [--dir DIR] [--url URL]")
    name = names[0]
    if name not in CATALOGUE:
        raise CommandError(f"unknown model {name!r}; known: {', '.join(CATALOGUE)}")
    model = CATALOGUE[name]
    progress = ProgressBar(sys.stderr, model.size, unit="bytes")
    try:
        path = fetch(model, args.dir or cache_dir(), url=args.url,
                     progress=lambda done, total: progress.update(done))
    finally:
        progress.finish()
    print(f"{name}: {path} (sha256 {model.sha256[:12]}... verified)")
    return 0
