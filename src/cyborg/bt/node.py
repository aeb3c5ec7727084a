r"""The node base classes and the lifecycle every node follows.

A node is ticked by its parent through :meth:`Node.execute`. One *activation* of a node spans
from the tick in which it starts until the tick in which it returns something other than
RUNNING, or until it is halted::

    idle --execute--> on_start() --> tick() --RUNNING--> (next tick) tick() ... --> on_end(status)
                                          \--not reached in a tick--> on_halt()   (exactly once)

* :meth:`Node.on_start` runs once when an activation begins (behavior3's ``open``).
* :meth:`Node.tick` runs on every tick and returns a :class:`~cyborg.bt.status.Status`.
* :meth:`Node.on_end` runs once when the activation completes (behavior3's ``close``).
* :meth:`Node.on_halt` runs once when a RUNNING node is abandoned: its parent stopped ticking it
  (a higher-priority branch took over, a timeout fired, the tree was stopped). Use it to cancel
  what the node started. Halting goes deepest first, so a child is halted before its parent.

Around each tick a node has two *extension points*, ``node.pre_tick`` and ``node.post_tick``
(:mod:`cyborg.bt.extension`, as BehaviorTree.CPP's pre- and post-tick callbacks); the tree's
hooks and its timing work through them.

A node's code may raise: the node then returns ERROR, the exception is logged once with its
traceback and the node's id, and the tree keeps ticking.

Write an action or condition by subclassing :class:`Action` or :class:`Condition`; its
``__init__`` keyword arguments are the node's properties in the editor (see
:mod:`cyborg.bt.properties`). The engine binds identity, memory and clock after construction, so
``__init__`` need not call ``super().__init__()``.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Iterator
from enum import StrEnum
from typing import TYPE_CHECKING, Any, ClassVar

from cyborg.bt.extension import ExtensionPoints, TickRecord
from cyborg.bt.limits import check_value_size
from cyborg.bt.status import ERROR, FAILURE, RUNNING, SUCCESS, NodeError, Status

if TYPE_CHECKING:
    from cyborg.bt.blackboard import Blackboard

log = logging.getLogger("cyborg.bt")

PreTick = Callable[["Node"], Status | None]
"""A ``node.pre_tick`` callback: a status means "do not tick, return this" (see
:mod:`cyborg.bt.extension`)."""
PostTick = Callable[["Node", Status], Status | None]
"""A ``node.post_tick`` callback: a status other than the one given replaces it."""


class Category(StrEnum):
    """The editor's node categories, plus ``tree`` for a subtree reference."""

    COMPOSITE = "composite"
    DECORATOR = "decorator"
    ACTION = "action"
    CONDITION = "condition"
    TREE = "tree"


class Node(ExtensionPoints):
    """Base class of every node.

    Subclass :class:`Action`, :class:`Condition`, :class:`Composite` or :class:`Decorator`.
    """

    category: ClassVar[Category]
    """The node's category, fixed by the base class it derives from."""
    _starts: ClassVar[bool] = False
    _ends: ClassVar[bool] = False
    requires: ClassVar[tuple[str, ...]] = ()
    """Keys of :attr:`Blackboard.resources <cyborg.bt.blackboard.Blackboard.resources>` the
    node cannot work without (the robot's nodes need ``"robot"``). A tree tells which of its
    nodes lack theirs (:meth:`Tree.missing_resources <cyborg.bt.tree.Tree.missing_resources>`),
    and ``stub_missing`` stands stubs in for them."""
    inputs: ClassVar[tuple[str, ...]] = ()
    """The node's input ports, in order (``"target?"``: optional). A behavior3 v1 file binds
    them to blackboard keys by position (its ``input`` array); :meth:`read` reads one."""
    outputs: ClassVar[tuple[str, ...]] = ()
    """The node's output ports, in order; the file's ``output`` array; :meth:`write`."""
    ports: dict[str, str] = {}
    """Port name (without ``?``) -> the blackboard key the file binds it to."""

    # Identity and wiring, bound by the builder after construction (see `bind`).
    uid: str = ""
    """Stable id, unique in the tree: the editor's node id, prefixed by the ids of the subtree
    references leading to it (``"<ref id>/<node id>"``)."""
    node_id: str = ""
    """The editor's node id."""
    name: str = ""
    """The editor's node name (``"MemSequence"``, ``"MoveTo"``, or a tree id for subtrees)."""
    title: str = ""
    """The raw title from the file, placeholders such as ``<location>`` unrendered."""
    label: str = ""
    """The title with ``<property>`` placeholders filled in, as the editor displays it."""
    description: str = ""
    tree_uid: str = ""
    """The (sub)tree instance the node belongs to; keys its tree-scope memory."""
    subtree_depth: int = 0
    """How many subtree references lie between the root tree and this node."""
    index: int = -1
    """Position in a depth-first, pre-order walk of the tree."""
    parent: Node | None = None
    children: list[Node] = []
    properties: dict[str, Any] = {}
    memory: dict[str, Any] = {}
    """Node-scope memory (behavior3's per-node blackboard scope)."""
    tree_memory: dict[str, Any] = {}
    """Tree-scope memory of the (sub)tree instance this node belongs to."""
    blackboard: Blackboard
    """The tree's blackboard; ``self.blackboard.get("key")`` reads the global scope."""
    status: Status | None = None
    """Status of the node's last tick; ``None`` when idle (never ticked, or halted)."""
    last_error: BaseException | None = None
    """The last exception the node's code raised, if any."""
    error_count: int = 0
    _record: TickRecord

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        # Skip the hook calls for classes that do not override them: most visits are
        # activations of nodes that finish at once, and two empty calls would double their cost.
        cls._starts = cls.on_start is not Node.on_start
        cls._ends = cls.on_end is not Node.on_end
        # Neither: an execute without the two tests (an execute not the engine's is kept).
        if cls.execute in _ENGINE_EXECUTES:
            lean = not (cls._starts or cls._ends)
            cls.execute = Node._execute_lean if lean else Node.execute  # type: ignore[method-assign]

    # ----------------------------------------------------------------- hooks to override
    def on_start(self) -> None:
        """Called once when an activation begins, before the first :meth:`tick`."""

    def tick(self) -> Status:
        """Does one step of work and says how it went. Every node class overrides it."""
        raise NotImplementedError(f"{type(self).__name__} does not implement tick()")

    def on_end(self, status: Status) -> None:
        """Called once when an activation completes with ``status`` (not RUNNING)."""

    def on_halt(self) -> None:
        """Called once when a RUNNING node is abandoned; cancel what it started."""

    # ----------------------------------------------------------------- ports
    def read(self, port: str, default: Any = None) -> Any:
        """The global blackboard value of input ``port``; ``default`` if unbound or unset."""
        key = self.ports.get(port)
        return default if key is None else self.blackboard.get(key, default)

    def write(self, port: str, value: Any) -> None:
        """Sets output ``port``'s key (unbound: no-op; ``None`` deletes; too large: NodeError)."""
        key = self.ports.get(port)
        if key is not None and value is None:
            self.blackboard.globals.pop(key, None)
        elif key is not None:
            check_value_size(f"output {port!r}", value)
            self.blackboard[key] = value

    # ----------------------------------------------------------------- engine
    @property
    def now(self) -> float:
        """Time of the current tick in seconds, from the tree's clock (simulated or real)."""
        return self._record.now

    def ms_since(self, key: str = "start") -> float:
        """Milliseconds from ``memory[key]`` (a time taken from :attr:`now`) to now.

        ``on_start`` usually takes that time. When the clock went back past it (a restarted
        simulation, a backward jump of ``/clock``), the count restarts from now, as ROS 2 resets
        its timers on a backward jump: a Wait never waits for time to pass its start again.
        """
        start = self.memory[key]
        now = self._record.now
        if now < start:
            self.memory[key] = start = now
        return elapsed_ms(now, start)

    def execute(self) -> Status:
        """Ticks this node once inside the tree's current tick. Parents call this, not tick().

        Goes through the extension points when this node uses one (see
        :mod:`cyborg.bt.extension`); otherwise they cost the test below, and one test only
        while no node of the tree uses them. A class that overrides neither :meth:`on_start`
        nor :meth:`on_end` runs :meth:`_execute_lean` instead, chosen when the class is made.
        """
        record = self._record
        if record.hooked and self in record.hooked:
            return self._execute_hooked()
        # The steps of ExtensionPoints._tick_once, inline: the path of nearly every visit.
        try:
            if self._starts and self.status is not RUNNING:
                self.on_start()
            status = self.tick()
            if status.__class__ is not Status:
                status = self._coerce(status)
        except Exception as exc:
            status = self._raised(exc)
        self.status = status
        record.visits.append((self, status))
        if status is RUNNING:
            record.running.append(self)
        elif self._ends:
            self._end(status)
        return status

    def _execute_lean(self) -> Status:
        """:meth:`execute` less the tests for :meth:`on_start` and :meth:`on_end`."""
        record = self._record
        if record.hooked and self in record.hooked:
            return self._execute_hooked()
        try:
            status = self.tick()
            if status.__class__ is not Status:
                status = self._coerce(status)
        except Exception as exc:
            status = self._raised(exc)
        self.status = status
        record.visits.append((self, status))
        if status is RUNNING:
            record.running.append(self)
        return status

    def halt(self) -> None:
        """Halts this node if it is RUNNING: its running descendants first, then itself.

        Each halted node's :meth:`on_halt` runs exactly once and its status becomes ``None``.
        Composites and decorators call this on children they stop ticking; the tree calls it
        at the end of a tick on every RUNNING node that was not reached.

        Children are visited even when this node is not RUNNING: a descendant may still be
        RUNNING under a child that completed this tick, and it must go first.
        """
        for child in self.children:
            child.halt()
        if self.status is not RUNNING:
            return
        self.status = None
        self._record.halted.append(self)
        try:
            self.on_halt()
        except Exception as exc:
            self._raised(exc, during="on_halt")

    def halt_children(self) -> None:
        """Halts every RUNNING child (and their descendants)."""
        for child in self.children:
            child.halt()

    def walk(self) -> Iterator[Node]:
        """This node and its descendants, depth first, pre-order, at any depth (no recursion)."""
        pending = [self]
        while pending:
            node = pending.pop()
            yield node
            pending.extend(reversed(node.children))

    def __repr__(self) -> str:
        return f"<{type(self).__name__} {self.label or self.name!r} uid={self.uid!r}>"

    # ----------------------------------------------------------------- internals
    def _end(self, status: Status) -> None:
        try:
            self.on_end(status)
        except Exception as exc:
            self._raised(exc, during="on_end")

    def _coerce(self, value: object) -> Status:
        """Accept ``True``/``False`` as SUCCESS/FAILURE; anything else is an error."""
        if value is True:
            return SUCCESS
        if value is False:
            return FAILURE
        raise TypeError(
            f"tick() returned {value!r} ({type(value).__name__}); expected a Status or a bool"
        )

    def _raised(self, exc: Exception, during: str = "tick") -> Status:
        """Record an exception from the node's code; log it the first time it is seen."""
        previous = self.last_error
        self.last_error = exc
        self.error_count += 1
        repeated = (
            previous is not None
            and type(previous) is type(exc)
            and previous.args == exc.args
        )
        if repeated:
            log.debug("node %s (%s) raised again in %s: %r", self.uid, self.label, during, exc)
        elif isinstance(exc, NodeError):
            log.error("node %s (%s, %s) returns ERROR in %s: %s; the tree keeps ticking",
                      self.uid, self.label, self.name, during, exc)
        else:
            log.error("node %s (%s, %s) raised in %s; it returns ERROR and the tree keeps "
                      "ticking", self.uid, self.label, self.name, during, exc_info=exc)
        return ERROR

    def bind(self, *, uid: str, node_id: str, name: str, title: str, label: str,
             description: str, properties: dict[str, Any], tree_uid: str, subtree_depth: int,
             blackboard: Blackboard, record: TickRecord) -> None:
        """Attaches the node to a tree. Called by the builder right after construction."""
        self.uid = uid
        self.node_id = node_id
        self.name = name
        self.title = title
        self.label = label
        self.description = description
        self.properties = properties
        self.tree_uid = tree_uid
        self.subtree_depth = subtree_depth
        self.blackboard = blackboard
        self.memory = blackboard.node_scope(uid)
        self.tree_memory = blackboard.tree_scope(tree_uid)
        self._record = record
        self.children = []
        self._rehook()  # a slot filled before the node was bound takes effect now

    def adopt(self, children: list[Node]) -> None:
        """Attaches ``children`` in order. Decorators also get :attr:`Decorator.child`."""
        self.children = children
        for child in children:
            child.parent = self

    def check(self) -> list[str]:
        """Problems with this node's configuration once its children are attached.

        Override to validate, e.g., thresholds against the number of children. Each string is
        reported as an error naming the node.
        """
        return []


_ENGINE_EXECUTES = (Node.execute, Node._execute_lean)


class Action(Node):
    """A leaf that does something in the world (drive, speak, charge)."""

    category = Category.ACTION

    def check(self) -> list[str]:
        """One problem if the action has children: a leaf takes none."""
        return _no_children(self)


class Condition(Node):
    """A leaf that checks something; ``tick`` may return a bool."""

    category = Category.CONDITION

    def check(self) -> list[str]:
        """One problem if the condition has children: a leaf takes none."""
        return _no_children(self)


class Composite(Node):
    """A node with an ordered list of children."""

    category = Category.COMPOSITE


class Decorator(Node):
    """A node with exactly one child, whose result it transforms."""

    category = Category.DECORATOR
    child: Node

    def adopt(self, children: list[Node]) -> None:
        """Attaches ``children`` and makes the first one :attr:`child`."""
        super().adopt(children)
        if children:
            self.child = children[0]

    def check(self) -> list[str]:
        """One problem unless exactly one child is attached."""
        if not self.children:
            return ["decorator has no child: connect one node below it in the editor"]
        if len(self.children) > 1:
            return [f"a decorator takes exactly one child, it has {len(self.children)}"]
        return []


def _no_children(node: Node) -> list[str]:
    if node.children:
        count = len(node.children)
        return [f"{node.category.value} nodes cannot have children; this one has {count}"]
    return []


def elapsed_ms(now: float, start: float) -> float:
    """Milliseconds from ``start`` to ``now`` (seconds), rounded to the nanosecond.

    The rounding absorbs floating-point noise, so that ``0.7 - 0.2`` counts as the 500 ms it
    is meant to be and a 500 ms Wait does not need an extra tick.
    """
    return round((now - start) * 1000.0, 6)


NodeFactory = Callable[..., Node]
"""Anything that builds a node from keyword properties: usually a Node subclass."""

__all__ = [
    "ERROR",
    "FAILURE",
    "RUNNING",
    "SUCCESS",
    "Action",
    "Category",
    "Composite",
    "Condition",
    "Decorator",
    "Node",
    "NodeFactory",
    "PostTick",
    "PreTick",
    "Status",
    "TickRecord",
    "elapsed_ms",
]
