"""``cyborg up --record [FILE]``: the whole run recorded beside the robot.

The recorder (:mod:`cyborg.record.component`) runs in ``cyborg up``'s process with the other
components and records every topic but images (add ``--record-images``) into ``FILE``,
by default ``cyborg_<date>_<time>.mcap`` in the current folder. Its metadata names the map and
the tree file the run uses and the cyborg version. Ctrl-C finishes the file with the rest of
the system.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from cyborg.bus.component import NodeSpec
from cyborg.record import recorder

AUTO = "auto"
"""What ``--record`` without a file name stands for: a name from the date and time."""


def add_record_options(parser: argparse.ArgumentParser) -> None:
    """Adds ``--record [FILE]`` and ``--record-images`` to ``cyborg up``."""
    parser.add_argument("--record", nargs="?", const=AUTO, default=None, metavar="FILE",
                        help="record the run into this MCAP file (default name: "
                             "cyborg_<date>_<time>.mcap); see docs/recording.md")
    parser.add_argument("--record-images", action="store_true",
                        help="with --record: record the camera's images too")


def record_nodes(args: argparse.Namespace, namespace: str, map_path: Path,
                 tree_path: Path) -> list[NodeSpec]:
    """The recorder's spec when ``--record`` was given, naming the run's map and tree."""
    if args.record is None:
        return []
    output = (time.strftime("cyborg_%Y-%m-%d_%H-%M-%S.mcap") if args.record == AUTO
              else args.record)
    return [NodeSpec("recorder", recorder.NAME, namespace,
                     {"output": str(Path(output).resolve()), "images": args.record_images,
                      "map": str(map_path), "tree": str(tree_path)},
                     where="recorder (--record)")]
