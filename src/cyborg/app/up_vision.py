"""The camera, detector and tracker ``cyborg up`` starts beside the simulated robot.

The simulated robot has no rendered camera, so the camera node plays recorded frames: by
default scikit-image's Middlebury "Motorcycle" stereo sample (left, right and depth, looped at
a few frames per second), or any source given with ``--camera``. The detector finds its model
by name (``--model``, default ``yolox_nano``); when no copy is on this machine it is downloaded
once into the cache with its SHA-256 checked. Without a model — offline and never fetched — the
robot runs without the detector and says why. The tracker
(:mod:`cyborg.perception.component`) places the detector's predictions on the map and
publishes the robot's ``objects``; it stamps as the camera does (the wall clock).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from cyborg.app.launch import under_robot
from cyborg.bus.component import NodeSpec
from cyborg.interfaces.detector import DEPTH, IMAGE
from cyborg.perception import component as perception
from cyborg.vision import VisionError
from cyborg.vision import component as vision
from cyborg.vision.models import CATALOGUE, fetch, find_model
from cyborg.vision.sources import anchored

CAMERA_SOURCE = "sample:motorcycle"
"""What ``cyborg up``'s camera plays unless told otherwise: a stereo sample with depth."""
CAMERA_RATE = 5.0
"""Frames per second ``cyborg up``'s camera plays: a few, to leave the robot its CPU."""
DETECTOR_THREADS = 1
"""Inference threads of ``cyborg up``'s detector, for the same reason."""


def add_vision_options(parser: argparse.ArgumentParser) -> None:
    """Adds ``--camera``, ``--model`` and ``--no-detector`` to ``cyborg up``."""
    parser.add_argument("--camera", default=CAMERA_SOURCE, metavar="SOURCE",
                        help="frames the camera plays: a video, folder, bag, camera:N "
                             f"(default {CAMERA_SOURCE})")
    parser.add_argument("--model", default=vision.MODEL, metavar="MODEL",
                        help=f"detector model file or name (default {vision.MODEL})")
    parser.add_argument("--no-detector", action="store_true",
                        help="start neither the camera nor the detector")


def model_for_up(name: str) -> Path | None:
    """The model's file, fetched into the cache if it is a known one; None when it cannot be had.

    Why not is printed on stderr.
    """
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
    """The camera, detector and tracker of the robot ``namespace``; none without a model."""
    if args.no_detector:
        return []
    model = model_for_up(args.model)
    if model is None:
        return []
    camera_ns = under_robot(namespace, vision.CAMERA_NAMESPACE)
    source = anchored(args.camera, Path.cwd())
    return [
        NodeSpec("camera", vision.CAMERA_NAME, camera_ns,
                 {"source": source, "rate": CAMERA_RATE}, where="camera (--camera)"),
        NodeSpec("detector", vision.DETECTOR_NAME,
                 under_robot(namespace, vision.DETECTOR_NAMESPACE),
                 {"model": str(model), "threads": DETECTOR_THREADS,
                  "image_topic": IMAGE.full_name(camera_ns),
                  "depth_topic": DEPTH.full_name(camera_ns)},
                 where="detector (--model)"),
        NodeSpec("tracker", perception.TRACKER_NAME, namespace, where="tracker"),
    ]
