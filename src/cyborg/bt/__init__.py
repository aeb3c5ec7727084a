"""The behaviour-tree engine: behavior3editor trees, run correctly and fast.

Load a tree exported by behavior3editor and tick it::

    from cyborg.bt import load_tree

    tree = load_tree("patrol.b3.json")
    snapshot = tree.tick()
    print(snapshot.status, snapshot.active)

Write your own nodes by subclassing :class:`Action`, :class:`Condition`, :class:`Decorator` or
:class:`Composite` and registering them with :func:`register`; attach background work to
composites with a :class:`Service` registered by :func:`register_service`. Run a tree at a
fixed rate with :class:`TickLoop`. This package does no I/O beyond reading tree files and
imports nothing else of cyborg.
"""

from cyborg.bt.blackboard import Blackboard
from cyborg.bt.builder import Subtree
from cyborg.bt.clock import Clock, ManualClock, MonotonicClock
from cyborg.bt.composites import (
    MemPriority,
    MemSequence,
    Parallel,
    Priority,
    ResumingSequence,
    Sequence,
)
from cyborg.bt.decorators import (
    Delay,
    ForceFailure,
    ForceSuccess,
    Inverter,
    Limiter,
    MaxTime,
    Repeater,
    RepeatUntilFailure,
    RepeatUntilSuccess,
    Retry,
    RunOnce,
    Timeout,
)
from cyborg.bt.editor_format import ProjectSpec, parse_project, read_project, render_title
from cyborg.bt.hooks import Hook, HookError, HookMode, TreeHooks
from cyborg.bt.leaves import Error, Failer, Runner, Succeeder, Wait
from cyborg.bt.loader import check_file, load_tree, loads_tree
from cyborg.bt.node import Action, Category, Composite, Condition, Decorator, Node
from cyborg.bt.problems import Problem, Severity, TreeLoadError
from cyborg.bt.registry import NodeRegistry, NodeType, default_registry, register
from cyborg.bt.service_registry import (
    ServiceRegistry,
    ServiceType,
    default_service_registry,
    register_service,
)
from cyborg.bt.service_runner import ServiceRunner, ServiceState
from cyborg.bt.services import Service, ServiceBoard, ServiceTiming
from cyborg.bt.snapshot import TickSnapshot, TreeStructure
from cyborg.bt.status import ERROR, FAILURE, RUNNING, SUCCESS, NodeError, Status
from cyborg.bt.tick_loop import TickLoop
from cyborg.bt.tree import Tree

__all__ = [
    "ERROR",
    "FAILURE",
    "RUNNING",
    "SUCCESS",
    "Action",
    "Blackboard",
    "Category",
    "Clock",
    "Composite",
    "Condition",
    "Decorator",
    "Delay",
    "Error",
    "Failer",
    "ForceFailure",
    "ForceSuccess",
    "Hook",
    "HookError",
    "HookMode",
    "Inverter",
    "Limiter",
    "ManualClock",
    "MaxTime",
    "MemPriority",
    "MemSequence",
    "MonotonicClock",
    "Node",
    "NodeError",
    "NodeRegistry",
    "NodeType",
    "Parallel",
    "Priority",
    "Problem",
    "ProjectSpec",
    "RepeatUntilFailure",
    "RepeatUntilSuccess",
    "Repeater",
    "ResumingSequence",
    "Retry",
    "RunOnce",
    "Runner",
    "Sequence",
    "Service",
    "ServiceBoard",
    "ServiceRegistry",
    "ServiceRunner",
    "ServiceState",
    "ServiceTiming",
    "ServiceType",
    "Severity",
    "Status",
    "Subtree",
    "Succeeder",
    "TickLoop",
    "TickSnapshot",
    "Timeout",
    "Tree",
    "TreeHooks",
    "TreeLoadError",
    "TreeStructure",
    "Wait",
    "check_file",
    "default_registry",
    "default_service_registry",
    "load_tree",
    "loads_tree",
    "parse_project",
    "read_project",
    "register",
    "register_service",
    "render_title",
]
