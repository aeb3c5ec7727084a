"""The tracker as a component: its parameters, their defaults, and how it starts.

:func:`start` is the ``tracker`` kind of launch files (see :mod:`cyborg.bus.component`) and
what ``cyborg up`` runs beside each robot's detector. Its node (``tracker`` unless named
otherwise) lives in the robot's namespace; its parameters, all read-only:

==================  =====================================================================
parameter           meaning (default)
==================  =====================================================================
``robot``           the robot's namespace, whose ``pose`` it reads and under which it
                    publishes ``objects`` (the node's namespace)
``detector``        the detector's namespace (the robot's detector: ``<robot>/detector``)
``labels``          labels to track, a string array as the detector's ``classes``
                    (empty: every label)
``gate``            metres a sighting may lie from an object to join it (1.0)
``forget_after``    seconds unseen after which an object is forgotten (5.0)
``use_sim_time``    the node's clock from ``/clock`` (false: the wall clock)
==================  =====================================================================

The defaults are the contract's (:mod:`cyborg.interfaces.perception`).
"""

from __future__ import annotations

import time

from cyborg.bus import Context, Node, SimClock
from cyborg.bus.component import NodeSpec
from cyborg.interfaces import detector, perception
from cyborg.perception.node import TrackerNode
from cyborg.perception.tracker import TrackerSettings

TRACKER_NAME = "tracker"
"""The tracker's node name unless told otherwise."""


class RunningTracker:
    """A started tracker: its node."""

    def __init__(self, tracker: TrackerNode) -> None:
        self.tracker = tracker

    def describe(self) -> str:
        """What it reads and what it publishes."""
        tracker = self.tracker
        return (f"tracker      {tracker.node.fq_name}: "
                f"{detector.PREDICTIONS.full_name(tracker.detector_namespace)} -> "
                f"{perception.OBJECTS.full_name(tracker.robot_namespace)}")

    def stop(self) -> None:
        """Stops refreshing and leaves the bus."""
        self.tracker.stop()
        self.tracker.node.destroy()


def start(context: Context, spec: NodeSpec) -> RunningTracker:
    """Starts a tracker from ``spec``; settings that make no tracker refuse it."""
    node = Node(spec.name, spec.namespace, context=context, parameters=spec.parameters)
    try:
        params = node.parameters

        def fixed(name: str, default: object, description: str) -> object:
            return params.declare(name, default, description, read_only=True)

        robot_ns = str(fixed("robot", "", "robot namespace (default: the node's)")) \
            or node.namespace
        detector_ns = str(fixed("detector", "", "detector namespace (default: the robot's)"))
        labels = fixed("labels", [""], "labels to track (empty: every label)")
        gate = fixed("gate", perception.ASSOCIATION_GATE, "association gate, m")
        forget_after = fixed("forget_after", perception.FORGET_AFTER, "forget after, s")
        sim_time = bool(fixed("use_sim_time", False, "time from /clock"))
        try:
            settings = TrackerSettings(gate=float(gate),  # type: ignore[arg-type]
                                       forget_after=float(forget_after))  # type: ignore[arg-type]
        except (TypeError, ValueError) as exc:
            raise spec.error(str(exc)) from exc
        now = SimClock(node).now if sim_time else time.time
        tracker = TrackerNode(node, robot_ns, detector_ns or None, settings=settings,
                              labels=[str(label) for label in labels  # type: ignore[attr-defined]
                                      if label], now=now)
    except BaseException:
        node.destroy()
        raise
    return RunningTracker(tracker)
