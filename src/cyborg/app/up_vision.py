"""The camera and detector ``cyborg up`` starts beside the simulated robot.

The simulated robot has no rendered camera, so the camera node plays recorded frames: by
default scikit-image's Middlebury "Motorcycle" stereo sample (left, right and depth, looped at
a few frames per second), or any source given with ``--camera``. The detector finds its model
by name (``--model``, default ``yolox_nano``); when no copy is on this machine it is downloaded
once into the cache with its SHA-256 checked. Without a model — offline and never fetched — the
robot runs without the detector and says why.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from cyborg.app.node_spec import NodeSpec
from cyborg.vision import VisionError
from cyborg.vision.models import CATALOGUE, fetch, find_model
from cyborg.vision.sources import anchored

DEFAULT_CAMERA_SOURCE = "sample:motorcycle"


def add_vision_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--camera", default=DEFAULT_CAMERA_SOURCE, metavar="SOURCE",
                        help="frames the camera plays: a video, folder, bag, camera:N "
                             f"(default {DEFAULT_CAMERA_SOURCE})")
    parser.add_argument("--model", default="yolox_nano", metavar="MODEL",
                        help="detector model file or name (default yolox_nano)")
    parser.add_argument("--no-detector", action="store_true",
                        help="start neither the camera nor the detector")


def model_for_up(name: str) -> Path | None:
    """The model's file, fetched into the cache if it is a known one; None (and a printed
    reason) when it cannot be had."""
    try:
        return find_model(name)
    except VisionError as missing:
        if name not in CATALOGUE:
            print(f"cyborg up: detector not started: {missing}", file=sys.stderr)
            return None
        print(f"cyborg up: fetching the detector model {name} (once) ...", file=sys.stderr,
              flush=True)
        try:
            return fetch(CATALOGUE[name], timeout=20.0)
        except VisionError as failed:
            print(f"cyborg up: detector not started: {failed}; give --model FILE or run "
                  f"`cyborg detect models fetch {name}` later", file=sys.stderr)
            return None


def vision_nodes(args: argparse.Namespace, namespace: str) -> list[NodeSpec]:
    if args.no_detector:
        return []
    model = model_for_up(args.model)
    if model is None:
        return []
    camera_ns = f"{namespace}/camera"
    source = anchored(args.camera, Path.cwd())
    return [
        NodeSpec("camera", "camera", camera_ns, {"source": source, "rate": 5.0},
                 where="camera (--camera)"),
        NodeSpec("detector", "detector", f"{namespace}/detector",
                 {"model": str(model), "threads": 1,
                  "image_topic": f"{camera_ns}/left/image_raw",
                  "depth_topic": f"{camera_ns}/depth/depth_registered"},
                 where="detector (--model)"),
    ]
