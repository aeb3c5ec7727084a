"""One followed robot as the pages hear of it: its messages to them, and what they were sent.

:class:`~cyborg.monitor.robot_hub.RobotHub` keeps a :class:`RobotOutbox` per robot beside its
:class:`~cyborg.monitor.robot_source.RobotSource`, and decides when to send; this module says
what: the ``rs``, ``path``, ``det``, ``obj`` and ``map_ref`` messages (docs/monitor.md, "The
map's data path") built from the source's latest state, and the marks of what every page
already has (the footprint, the current goal and the running node go in an ``rs`` only when
they changed).
A :class:`Throttle` spaces the messages of one kind out (paths, detections, tracked objects).
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

from cyborg.monitor.map_store import StoredMap
from cyborg.monitor.robot_source import RobotSource


@dataclass
class Throttle:
    """Sends the newest of a stream at most once per ``interval`` s, its last one too.

    The stream's items are numbered (``id``); :meth:`wait` says whether the newest is due.
    """

    interval: float
    sent: int = 0
    """The id last sent."""
    at: float = -float("inf")
    """When it was sent (monotonic s)."""
    later: bool = False
    """A call to send the newest later is scheduled."""

    def wait(self, newest: int, now: float) -> float | None:
        """None when ``newest`` was sent; else how long until it may go (0 or less: now)."""
        if newest == self.sent:
            return None
        return self.at + self.interval - now

    def mark(self, newest: int, now: float) -> None:
        """Notes that ``newest`` went out at ``now``."""
        self.sent, self.at = newest, now


@dataclass
class RobotOutbox:
    """What the hub keeps about one followed robot: its source, and what the pages were sent."""

    source: RobotSource
    path_throttle: Throttle
    detections_throttle: Throttle
    objects_throttle: Throttle
    seq: int = 0
    last: float = -float("inf")
    """When the robot's changes were last sent (monotonic s)."""
    footprint_sent: int = 0
    """The footprint id last sent to the pages."""
    node: str = ""
    """The label of the node running now in the robot's tree ("" for none)."""
    node_sent: str = ""
    goal_sent: dict[str, Any] | None = None
    """The current goal last sent to the pages."""
    map: StoredMap | None = None
    building: bool = False
    """The robot's map is being laid out."""

    @property
    def namespace(self) -> str:
        """The robot's namespace."""
        return self.source.namespace

    def rs_message(self, *, scan: bool, everything: bool = False) -> dict[str, Any] | None:
        """The robot's ``rs``, or None before its first pose.

        With the scan if ``scan``; with what pages keep (footprint, goal, node) when it changed
        since the last ``rs`` to every page (:meth:`sent_to_all`), or always if ``everything``.
        """
        source = self.source
        pose = source.pose
        if pose is None:
            return None  # nothing to place the rest on yet
        self.seq += 1
        message: dict[str, Any] = {"t": "rs", "ns": source.namespace, "seq": self.seq,
                                   "p": pose}
        if scan and source.scan is not None:
            message["sc"] = source.scan
        if source.footprint is not None and (
                everything or source.footprint_id != self.footprint_sent):
            message["fp"] = source.footprint
        if (everything and source.goal is not None) or source.goal != self.goal_sent:
            message["goal"] = source.goal
        if (everything and self.node) or self.node != self.node_sent:
            message["node"] = self.node
        if source.state is not None:
            message["st"] = source.state
        if source.battery is not None:
            message["bat"] = source.battery
        path = source.path
        if path is not None:
            message["pid"] = path["id"]
        return message

    def sent_to_all(self) -> None:
        """Notes that every page now has the footprint, goal and node (an ``rs`` went to all)."""
        self.footprint_sent, self.node_sent = self.source.footprint_id, self.node
        self.goal_sent = self.source.goal

    def unsent(self) -> bool:
        """Whether the pages lack the running node (which the source does not track)."""
        return self.node != self.node_sent

    def path_message(self) -> dict[str, Any] | None:
        """The robot's ``path``, or None before its first."""
        path = self.source.path
        if path is None:
            return None
        return {"t": "path", "ns": self.namespace, "id": path["id"], "xy": path["xy"]}

    def detections_message(self) -> dict[str, Any] | None:
        """The robot's ``det``: what its detector saw last, placed on the map; None before."""
        seen = self.source.detections
        if seen is None:
            return None
        return {"t": "det", "ns": self.namespace, "id": seen["id"], "d": seen["d"]}

    def objects_message(self, *, within: float | None = None) -> dict[str, Any] | None:
        """The robot's ``obj``: what its tracker follows; None before it, or older than ``within``.

        ``within`` keeps a page that starts to look from being sent a list the tracker
        stopped renewing long ago.
        """
        seen = self.source.objects
        if seen is None or (within is not None and time.monotonic() - seen["at"] > within):
            return None
        return {"t": "obj", "ns": self.namespace, "id": seen["id"], "stamp": seen["stamp"],
                "o": seen["o"]}

    def map_ref(self) -> dict[str, Any]:
        """The robot's ``map_ref``: its map's key, address, file name and counts (or nulls)."""
        stored = self.map
        return {"t": "map_ref", "ns": self.namespace,
                "key": stored.key if stored else None, "url": stored.url if stored else None,
                "source": stored.source if stored else None,
                "counts": stored.counts if stored else None}
