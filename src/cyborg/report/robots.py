"""Which robots a recording holds, and which of its topics belong to each.

A robot is found by any topic of its contract (:mod:`cyborg.interfaces.robot`) under its
namespace: ``/robot1/pose`` of type ``Pose2D`` or ``/robot1/battery_status`` of type
``BatteryStatus`` both name ``/robot1``, so a recording that lacks one topic still shows the
robot. Its tree runner lives under ``<robot>/bt`` and its detector under ``<robot>/detector``,
as ``cyborg up`` places them (:data:`~cyborg.interfaces.tree_runner.RUNNER_UNDER_ROBOT`,
:data:`~cyborg.interfaces.detector.DETECTOR_UNDER_ROBOT`); a tree runner that drives no robot
of the recording becomes a robot of its own, with only a tree to show.

:class:`RobotTopics` names the topics a report reads for one robot; :func:`wanted` says which
topics of a recording are decoded at all.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from cyborg.interfaces import detector, perception, robot, tree_runner
from cyborg.interfaces.contract import Topic

ROBOT_TOPICS: tuple[Topic, ...] = (robot.POSE, robot.BATTERY_STATUS, robot.PATH_STATE,
                                   robot.CURRENT_GOAL, robot.MAP_GEOMETRY, robot.BUMPER_STATE)
"""The robot's topics a report reads (each also tells that a robot is there)."""
TREE_TOPICS: tuple[Topic, ...] = (tree_runner.STRUCTURE, tree_runner.STATUS)
DETECTOR_TOPICS: tuple[Topic, ...] = (detector.DETECTIONS, detector.PREDICTIONS)
TRACKER_TOPICS: tuple[Topic, ...] = (perception.OBJECTS,)
"""The robot's tracker's topics: its tracked objects, under the robot's namespace."""
CLOCK_TOPIC = robot.CLOCK.name
"""Simulated time, when a simulator ran (:mod:`cyborg.report.clocks`)."""
LOG_TOPIC = "/rosout"
"""ROS 2's log topic; read when a recording holds it."""
LOG_TYPE = "rcl_interfaces/msg/Log"


@dataclass(frozen=True)
class RobotTopics:
    """The full names of one robot's topics, recorded or not."""

    namespace: str
    tree: str
    """The namespace of its tree runner."""
    detector: str
    """The namespace of its detector."""
    has_robot: bool = True
    """False for a tree runner that drives no robot of the recording."""

    def topic(self, contract: Topic[Any]) -> str:
        """The full name of one of the robot's (or its runner's, or detector's) topics."""
        if contract in TREE_TOPICS:
            return contract.full_name(self.tree)
        if contract in DETECTOR_TOPICS:
            return contract.full_name(self.detector)
        return contract.full_name(self.namespace)

    @property
    def title(self) -> str:
        """How the report names it: ``robot /cyborg`` or ``tree runner /bt``."""
        return f"robot {self.namespace}" if self.has_robot else f"tree runner {self.tree}"


def _namespace_of(topic: str, type_name: str, contracts: tuple[Topic, ...]) -> str | None:
    for contract in contracts:
        suffix = "/" + contract.name
        if type_name == contract.type_name and topic.endswith(suffix):
            return topic.removesuffix(suffix) or "/"
    return None


def find_robots(topics: dict[str, str]) -> list[RobotTopics]:
    """The robots (and lone tree runners) of a recording, from its topics and their types."""
    robots: set[str] = set()
    runners: set[str] = set()
    for topic, type_name in topics.items():
        namespace = _namespace_of(topic, type_name, ROBOT_TOPICS)
        if namespace is not None:
            robots.add(namespace)
        runner = _namespace_of(topic, type_name, TREE_TOPICS)
        if runner is not None:
            runners.add(runner)
    found = [RobotTopics(namespace, _under(namespace, tree_runner.RUNNER_UNDER_ROBOT),
                         detector.detector_of_robot(namespace))
             for namespace in sorted(robots)]
    driven = {item.tree for item in found}
    found += [RobotTopics(tree_runner.robot_of_runner(runner) or runner, runner,
                          detector.detector_of_robot(runner), has_robot=False)
              for runner in sorted(runners - driven)]
    return found


def _under(namespace: str, part: str) -> str:
    return namespace.rstrip("/") + part


def wanted(topic: str, type_name: str) -> bool:
    """Whether a report decodes ``topic`` (of ``type_name``): the topics above, anywhere."""
    if topic == LOG_TOPIC:
        return type_name == LOG_TYPE
    if topic == CLOCK_TOPIC:
        return type_name == robot.CLOCK.type_name
    return any(_namespace_of(topic, type_name, (contract,)) is not None
               for contract in (*ROBOT_TOPICS, *TREE_TOPICS, *DETECTOR_TOPICS, *TRACKER_TOPICS))
