"""The node registry: which Python class implements each node name in the editor.

Register your own nodes with the :func:`register` decorator::

    from cyborg.bt import Action, Status, register

    @register("Bedtime?")          # the name used in behavior3editor; default: the class name
    class Bedtime(Condition):
        def __init__(self, hour: int = 22) -> None:
            self.hour = hour
        def tick(self) -> Status: ...

Another package can add nodes without being imported by hand, by declaring an entry point in
the group ``cyborg.nodes`` (in its ``pyproject.toml``)::

    [project.entry-points."cyborg.nodes"]
    my_nodes = "my_package.nodes"          # a module: importing it runs its @register lines
    Greet = "my_package.nodes:Greet"       # or one class, registered under the entry's name

:func:`default_registry` holds the stock nodes, everything registered with the decorator and
every entry point's nodes.

A name is kept by the class that took it: registering another class under a stock or robot
node's name (``Say``, ``Sequence``) raises :class:`~cyborg.bt.named_registry.NameTakenError`,
which names both classes and where each comes from, unless you mean it:
``@register("Say", override=True)``.
"""

from __future__ import annotations

import importlib
import inspect
import logging
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Any, TypeVar, overload

from cyborg.bt import (
    blackboard_nodes,
    composites,
    decorators,
    leaves,
    v1_controls,
    v1_data,
    v1_math,
)
from cyborg.bt.named_registry import NamedRegistry
from cyborg.bt.node import Category, Node
from cyborg.bt.properties import Signature, signature_of
from cyborg.bt.resources import requirements_of

ENTRY_POINT_GROUP = "cyborg.nodes"

N = TypeVar("N", bound=type[Node])


@dataclass(frozen=True)
class NodeType:
    """A registered node: its editor name, implementing class and properties."""

    name: str
    cls: type[Node]
    signature: Signature
    origin: str
    """Where it came from: ``stock``, a module name, or ``entry point <name>``."""

    @property
    def category(self) -> Category:
        """The node class's category (action, condition, composite or decorator)."""
        return self.cls.category

    @property
    def requires(self) -> tuple[str, ...]:
        """The resources the node needs: declared, or fetched (``robot_of``; bt.resources)."""
        return requirements_of(self.cls)


class NodeRegistry(NamedRegistry[NodeType]):
    """Maps editor node names to node classes."""

    kind = Node

    def add(self, cls: type, name: str | None = None, *, origin: str = "",
            override: bool = False) -> NodeType:
        """Registers ``cls`` under ``name`` (default: the class name); returns what holds it.

        Raises :class:`TypeError` for a class that is not a node of one of the four
        categories, :class:`ValueError` for an empty name, and
        :class:`~cyborg.bt.named_registry.NameTakenError` for a name another class has, unless
        ``override`` (:meth:`~cyborg.bt.named_registry.NamedRegistry.enter`).
        """
        if not (inspect.isclass(cls) and issubclass(cls, Node)):
            raise TypeError(f"{cls!r} is not a Node subclass")
        if not hasattr(cls, "category"):
            raise TypeError(
                f"{cls.__name__} must derive from Action, Condition, Composite or Decorator"
            )
        key = name if name is not None else cls.__name__
        if not key:
            raise ValueError("a node name cannot be empty")
        node_type = NodeType(key, cls, signature_of(cls), origin or cls.__module__)
        return self.enter(node_type, override=override)

    def types(self) -> list[NodeType]:
        """All registered nodes, sorted by name."""
        return [self._types[name] for name in self.names()]

    def registered(self) -> NodeRegistry:
        """Where :func:`register` puts nodes."""
        return _REGISTERED

    def load_entry_points(self, group: str = ENTRY_POINT_GROUP) -> list[str]:
        """Registers the nodes of every installed entry point in ``group`` (see the base)."""
        return super().load_entry_points(group)

    def import_modules(self, modules: Iterable[str]) -> None:
        """Imports modules whose ``@register`` lines add nodes (``--nodes my_pkg.nodes``).

        Raises :class:`NodeModuleError` naming the first module that cannot be imported.
        """
        for module in modules:
            try:
                importlib.import_module(module)
            except Exception as exc:
                raise NodeModuleError(f"cannot import node module {module!r}: "
                                      f"{type(exc).__name__}: {exc}") from exc
        self._types.update(_REGISTERED._types)


class NodeModuleError(ImportError):
    """A module of node classes could not be imported; the message names it and why."""


_REGISTERED = NodeRegistry()
"""Where :func:`register` puts nodes; :func:`default_registry` starts from it."""


@overload
def register(name: N, /) -> N: ...
@overload
def register(name: str | None = None, /, *, override: bool = False) -> Callable[[N], N]: ...
def register(name: Any = None, /, *, override: bool = False) -> Any:
    """Class decorator: makes a node available to trees under ``name`` (default: class name).

    A name another class has (a stock or robot node's) is refused with
    :class:`~cyborg.bt.named_registry.NameTakenError` unless ``override=True``.
    """
    if inspect.isclass(name) and issubclass(name, Node):
        _REGISTERED.add(name)
        return name

    def decorate(cls: N) -> N:
        _REGISTERED.add(cls, name, override=override)
        return cls

    return decorate


STOCK_NODES: tuple[type[Node], ...] = (
    composites.Sequence, composites.Priority, composites.MemSequence, composites.MemPriority,
    composites.Parallel, composites.ResumingSequence,
    decorators.Inverter, decorators.Repeater, decorators.RepeatUntilFailure,
    decorators.RepeatUntilSuccess, decorators.MaxTime, decorators.Limiter, decorators.Retry,
    decorators.Timeout, decorators.ForceSuccess, decorators.ForceFailure, decorators.Delay,
    decorators.RunOnce,
    leaves.Failer, leaves.Succeeder, leaves.Runner, leaves.Error, leaves.Wait,
    blackboard_nodes.Log, blackboard_nodes.IsNull, blackboard_nodes.NotNull,
    # behavior3 v1 (behavior3-ts, behavior3lua) stock nodes; see docs/behavior3-v1.md
    v1_controls.IfElse, v1_controls.ParallelAll, v1_controls.Race, v1_controls.Switch,
    v1_controls.Case, v1_controls.Watchdog, v1_controls.Once, v1_controls.AlwaysRunning,
    v1_controls.Assert, v1_controls.Repeat, v1_controls.RetryUntilSuccess,
    v1_controls.RetryUntilFailure, v1_controls.ForEach, v1_controls.Filter,
    v1_controls.WaitForCount,
    v1_data.Check, v1_data.Calculate, v1_data.Let, v1_data.Now, v1_data.Clear, v1_data.Includes,
    v1_data.Push, v1_data.Concat, v1_data.Index, v1_data.GetField, v1_data.SetField,
    v1_data.RandomIndex, v1_math.Math, v1_math.Cmp, v1_math.Random,
)
"""The nodes every registry starts with: behavior3editor's palette, behavior3 v1's stock
nodes and a few more."""

for _cls in STOCK_NODES:
    _REGISTERED.add(_cls, origin="stock")


def default_registry(*, entry_points: bool = True) -> NodeRegistry:
    """A new registry of every node a tree may use.

    It holds the stock nodes, every ``@register``-ed node and, with ``entry_points``, the nodes
    of installed entry points (one that cannot be loaded is logged and skipped).
    """
    registry = _REGISTERED.copy()
    if entry_points:
        for problem in registry.load_entry_points():
            logging.getLogger("cyborg.bt").warning("skipping node %s", problem)
    return registry
