"""The camera and detector ``cyborg up`` gives the simulated robot: simulated, or real.

By default (``--camera sim``) the simulator's own camera (:mod:`cyborg.sim.camera`) detects
the people walking on the map and the objects placed on it, and publishes what the detector
would, on the detector's topics: no frames, no model. ``--camera real`` starts the real
detector instead, on recorded frames played by the camera node: scikit-image's Middlebury
"Motorcycle" stereo sample (left, right and depth, looped at a few frames per second); any
other ``--camera`` value is a source of frames for it (a video, folder, bag, camera:N). The
tree reads the same topics either way. The detector finds its model by name (``--model``,
default ``yolox_nano``); when no copy is on this machine it is downloaded once into the cache
with its SHA-256 checked. Without a model — offline and never fetched — the robot runs without
the detector and says why. Either way the tracker (:mod:`cyborg.perception.component`)
places the detections on the map and publishes the robot's ``objects``; it stamps as the
camera does (simulated time for the simulated camera, the wall clock for recorded frames).
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

SIMULATED = "sim"
"""``--camera`` for the simulator's camera: the default."""
REAL = "real"
"""``--camera`` for the real detector on :data:`CAMERA_SOURCE`."""
CAMERA_SOURCE = "sample:motorcycle"
"""What ``cyborg up``'s camera plays with ``--camera real``: a stereo sample with depth."""
CAMERA_RATE = 5.0
"""Frames per second ``cyborg up``'s camera plays: a few, to leave the robot its CPU."""
DETECTOR_THREADS = 1
"""Inference threads of ``cyborg up``'s detector, for the same reason."""


def add_vision_options(parser: argparse.ArgumentParser) -> None:
    """Adds ``--camera``, ``--model`` and ``--no-detector`` to ``cyborg up``."""
    parser.add_argument("--camera", default=SIMULATED, metavar="SOURCE",
                        help=f"{SIMULATED}: the simulator's camera detects its people and "
                             f"objects (default); {REAL}: the detector on sample frames "
                             f"({CAMERA_SOURCE}); else frames for the detector: a video, "
                             "folder, bag, camera:N")
    parser.add_argument("--model", default=vision.MODEL, metavar="MODEL",
                        help=f"detector model file or name, for a real camera (default "
                             f"{vision.MODEL})")
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


def simulated_camera(args: argparse.Namespace) -> dict[str, bool]:
    """The simulator's ``camera`` parameter: on for ``--camera sim`` (not ``--no-detector``)."""
    return {"camera": args.camera == SIMULATED and not args.no_detector}


def vision_nodes(args: argparse.Namespace, namespace: str) -> list[NodeSpec]:
    """The camera, the real detector and the tracker of the robot ``namespace``.

    With the simulated camera only the tracker: the simulator's camera publishes what the
    detector would, stamped on simulated time, so the tracker runs on ``/clock`` too. None with
    ``--no-detector``, and neither camera nor detector nor tracker without a model.
    """
    if args.no_detector:
        return []
    if args.camera == SIMULATED:
        return [NodeSpec("tracker", perception.TRACKER_NAME, namespace, {"use_sim_time": True},
                         where="tracker")]
        return []
    model = model_for_up(args.model)
    if model is None:
        return []
    camera_ns = under_robot(namespace, vision.CAMERA_NAMESPACE)
    source = anchored(CAMERA_SOURCE if args.camera == REAL else args.camera, Path.cwd())
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
