"""The tree runner's interface, between the runner and the monitor.

What :mod:`cyborg.runner.tree_runner` (with :mod:`cyborg.runner.tree_control`) serves and the
monitor (:mod:`cyborg.monitor.source`) uses.

Under the runner's namespace (:data:`NAMESPACE`, ``/cyborg/bt`` by default, as in 2018):

==========================  ==================================  ==================================
name                        type                                what
==========================  ==================================  ==================================
``behavior_tree``           cyborg_msgs/BehaviorTree            latched: the structure as JSON
``behavior_tree_updates``   cyborg_msgs/BehaviorTreeNodes       latched: ids of the active path
``enabled``                 std_msgs/Bool                       latched: whether the tree ticks
``stopped``                 std_msgs/Bool                       latched: whether ``stop`` halted it
                                                                and no ``enable(true)`` came since
``status``                  cyborg_msgs/BehaviorTreeStatus      every tick: what ran, how it ended
``hooks``                   cyborg_msgs/BehaviorTreeHooks       latched: hooks set, where a tick
                                                                waits (:class:`HookAction`)
``services``                cyborg_msgs/ServiceStates           latched: the services on the
                                                                composites (docs/services.md):
                                                                whether each runs, when it last
                                                                ran, what it wrote, its error
``enable``                  std_srvs/SetBool                    run or pause the tree
``stop``                    std_srvs/Trigger                    halt the tree and keep it halted
                                                                until ``enable(true)`` (STOP)
``reload``                  cyborg_msgs/ReloadTree              load the file again
``control``                 cyborg_msgs/ControlNode             set or clear a hook on one node
``resume``, ``step``        std_srvs/Trigger                    go on from a breakpoint
``get_blackboard``          cyborg_msgs/GetBlackboard           the blackboard as JSON
==========================  ==================================  ==================================

A runner is recognised on the bus by its :data:`STRUCTURE` topic (:func:`runner_namespace`).
``services`` (:data:`SERVICE_STATES`) carries the state of every service attached to a
composite of the tree that ticks (of a mode file: the current mode's tree), one
``cyborg_msgs/ServiceState`` each, in tree order. It is published when any of them started,
stopped, ran, wrote or failed, at most :data:`SERVICE_STATES_PER_SECOND` times a second (the
newest states go out when the interval has passed), and latched, so a monitor that comes late
gets the last. A tree without services publishes nothing on it; when a reload or a mode switch
leaves a tree without services after one with them, one message with no services says so.

**Stop and pause.** ``stop`` (the monitor's red STOP, ``cyborg bt stop``) halts the tree as
``enable(false)`` does and says so on ``stopped``, latched, so that every monitor, one that
comes later included, shows the tree as *stopped* rather than paused; only ``enable(true)``
(Resume, ``cyborg bt enable``) runs it again and clears ``stopped``.

Hook codes and statuses come from ControlNode.srv; the statuses equal the engine's
(:class:`cyborg.bt.Status`), which the tests check.
"""

from __future__ import annotations

from enum import IntEnum

from cyborg.bus.msgs.cyborg_msgs.msg import (
    BehaviorTree,
    BehaviorTreeHooks,
    BehaviorTreeNodes,
    BehaviorTreeStatus,
    ServiceStates,
)
from cyborg.bus.msgs.cyborg_msgs.srv import (
    ControlNode,
    ControlNode_Request,
    GetBlackboard,
    ReloadTree,
)
from cyborg.bus.msgs.std_msgs.msg import Bool
from cyborg.bus.msgs.std_srvs.srv import SetBool, Trigger
from cyborg.interfaces.contract import Service, Topic

NAMESPACE = "/cyborg/bt"
"""The tree runner's namespace unless told otherwise."""

# ---------------------------------------------------------------------- topics
STRUCTURE = Topic("behavior_tree", BehaviorTree, latched=True)
ACTIVE_PATH = Topic("behavior_tree_updates", BehaviorTreeNodes, latched=True)
ENABLED = Topic("enabled", Bool, latched=True)
STOPPED = Topic("stopped", Bool, latched=True)
STATUS = Topic("status", BehaviorTreeStatus)
HOOKS = Topic("hooks", BehaviorTreeHooks, latched=True)
SERVICE_STATES = Topic("services", ServiceStates, latched=True)
TOPICS: tuple[Topic, ...] = (STRUCTURE, ACTIVE_PATH, ENABLED, STOPPED, STATUS, HOOKS,
                             SERVICE_STATES)

SERVICE_STATES_PER_SECOND = 4.0
"""Most ``services`` messages a runner publishes a second (wall time)."""

# ---------------------------------------------------------------------- services
ENABLE = Service("enable", SetBool)
STOP = Service("stop", Trigger)
RELOAD = Service("reload", ReloadTree)
CONTROL = Service("control", ControlNode)
RESUME = Service("resume", Trigger)
STEP = Service("step", Trigger)
GET_BLACKBOARD = Service("get_blackboard", GetBlackboard)
SERVICES: tuple[Service, ...] = (ENABLE, STOP, RELOAD, CONTROL, RESUME, STEP, GET_BLACKBOARD)

# ---------------------------------------------------------------------- values in the messages


class HookAction(IntEnum):
    """ControlNode's ``action`` (and BehaviorTreeHooks' ``actions``, which lack CLEAR)."""

    CLEAR = ControlNode_Request.CLEAR
    DISABLE = ControlNode_Request.DISABLE
    FORCE = ControlNode_Request.FORCE
    BREAKPOINT = ControlNode_Request.BREAKPOINT

    @property
    def label(self) -> str:
        """Lower-case name, as the monitor's page and the engine's hook modes say it."""
        return self.name.lower()


class HookStatus(IntEnum):
    """ControlNode's ``status``: what a disabled or forced node returns."""

    SUCCESS = ControlNode_Request.SUCCESS
    FAILURE = ControlNode_Request.FAILURE
    RUNNING = ControlNode_Request.RUNNING


def runner_namespace(topic: str, type_name: str) -> str | None:
    """The namespace of the runner that publishes ``topic`` of ``type_name``, or None.

    Only a runner's structure topic names one (``/cyborg/bt/behavior_tree`` → ``/cyborg/bt``);
    ``type_name`` is the topic's type as the bus graph shows it.
    """
    suffix = "/" + STRUCTURE.name
    if type_name != STRUCTURE.type_name or not topic.endswith(suffix):
        return None
    return topic.removesuffix(suffix) or "/"


RUNNER_UNDER_ROBOT = "/bt"
"""Where a robot's tree runner lives under the robot's namespace (``/cyborg`` → ``/cyborg/bt``),
as ``cyborg up`` places it (``app.launch.under_robot``)."""


def robot_of_runner(namespace: str) -> str | None:
    """The namespace of the robot that the tree runner under ``namespace`` drives, or None.

    By the convention of :data:`RUNNER_UNDER_ROBOT`: ``/robot1/bt`` → ``/robot1``; a runner
    elsewhere names no robot.
    """
    robot = namespace.removesuffix(RUNNER_UNDER_ROBOT)
    return robot if robot != namespace and robot else None
