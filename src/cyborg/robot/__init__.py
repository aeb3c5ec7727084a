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
========================  ==========  =====================================================

Two services (:mod:`cyborg.robot.watch_services`) keep the robot's state in the blackboard while
the composite they are attached to runs: ``BatteryWatch{key,low}`` (the battery reading) and
``ClosestGoal{key}`` (the closest goal by path length).

They act on the robot through :class:`~cyborg.robot.interface.Robot` (see that module); the tree
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
    safety,
    watch_services,
)
from cyborg.robot.interface import ROBOT, Robot, RobotError, robot_of

__all__ = ["ROBOT", "Robot", "RobotError", "battery", "battery_board", "blackboard_compare",
           "docking", "goals", "move_to", "robot_of", "safety", "watch_services"]
