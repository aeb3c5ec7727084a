"""``cyborg detect bus:TOPIC``: frames from camera topics on the bus."""

from __future__ import annotations

import argparse
import os

from cyborg.app.bus_options import DEFAULT_ROUTER, bus_context
from cyborg.bus import Context, Node
from cyborg.vision import CameraTopics
from cyborg.vision.bus_source import BusSource


class BusHandle:
    """The context and node a bus source reads through, closed after it."""

    def __init__(self, context: Context, node: Node) -> None:
        self.context, self.node = context, node

    def close(self) -> None:
        """Leaves the bus."""
        self.node.destroy()
        self.context.close()


def open_bus_source(args: argparse.Namespace) -> tuple[BusSource, BusHandle]:
    """Frames from the camera topics ``bus:TOPIC`` and the options name, and their handle."""
    topics = CameraTopics(args.source.removeprefix("bus:"), args.depth_topic or "",
                          args.right_topic or "")
    context, _ = bus_context(list(args.connect), DEFAULT_ROUTER)
    node = Node(f"detect_{os.getpid()}", "/", context=context)
    return BusSource(node, topics, idle_timeout=args.duration), BusHandle(context, node)
