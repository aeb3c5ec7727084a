"""The robot's behaviour nodes, registered under the names trees use in behavior3editor.

========================  ==========  =====================================================
name                      category    what it does
========================  ==========  =====================================================
MoveTo{location,radius}   action      drive to a map goal; stall detection, retries,
                                      back-off while the robot is unreachable, cancel
CheckBattery{threshold}   decorator   latching guard: tick the child while the battery is low
Charge{target}            action      dock if needed; RUNNING until charged to ``target`` %
Dock, Undock              action      dock / undock and wait until done
ClosestGoal{key}          action      closest goal by path length into the blackboard
DistanceToGoal{location}  condition   path length to a goal into the blackboard
BlackboardCompare{key,    decorator   tick the child when a blackboard entry matches
value,equal}
ReadBattery{key}          action      the battery reading into the global blackboard
StopSafely                action      ask the robot to stop (it waits where it is)
CallForHelp{reason,       action      call for help on the robot's ``help`` topic, again
every}                                every ``every`` s; RUNNING
ObjectDetected{label,     condition   an object of ``label`` near, sure and fresh enough
maxDistance,minConfidence,
maxAge}
ClosestObject{label,key}  action      the nearest object (bearing, distance, map position)
                                      into the blackboard
FaceObject{label,         action      turn toward the nearest object of ``label``
tolerance}
ApproachObject{label,     action      drive up to it, stop ``stopDistance`` m away
stopDistance}
Say{text}                 action      speak a sentence; ``{closest.label}`` fills in
                                      blackboard values
OncePerObject{key,        decorator   tick the child for the object ``ClosestObject``
seconds,gap}                          wrote, unless done for it (or anyone) lately
========================  ==========  =====================================================

The perception nodes (:mod:`~cyborg.robot.object_nodes`, :mod:`~cyborg.robot.object_motion`,
:mod:`~cyborg.robot.say`) read what the robot's tracker follows on the map and speak through
:class:`~cyborg.robot.perceiving.PerceivingRobot` (see docs/perception.md).

Two services (:mod:`cyborg.robot.watch_services`) keep the robot's state in the blackboard while
the composite they are attached to runs: ``BatteryWatch{key,low}`` (the battery reading) and
``ClosestGoal{key}`` (the closest goal by path length).

They act on the robot through :class:`~cyborg.robot.protocol.Robot` (see that module); the tree
runner (:mod:`cyborg.runner.tree_runner`) provides one on the bus. This package is an entry
point of the groups ``cyborg.nodes`` and ``cyborg.services``, so every registry built with
:func:`cyborg.bt.default_registry` (:func:`cyborg.bt.default_service_registry`) knows these nodes
(services) — a user's own package adds nodes the same
way (see the README).
"""

from cyborg.robot import (
    battery,
    battery_board,
    blackboard_compare,
    docking,
    goals,
    move_to,
    object_motion,
    object_nodes,
    once_per_object,
    safety,
    say,
    watch_services,
)
from cyborg.robot.protocol import ROBOT, Robot, RobotError, robot_of

__all__ = ["ROBOT", "Robot", "RobotError", "battery", "battery_board", "blackboard_compare",
           "docking", "goals", "move_to", "object_motion", "object_nodes", "once_per_object",
           "robot_of", "safety", "say", "watch_services"]
