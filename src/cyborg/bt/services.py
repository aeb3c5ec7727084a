r"""Services: background work attached to a composite, keeping the blackboard fresh.

A *service* hangs on a composite node (Sequence, Priority, Parallel, ...) and runs while that
composite's branch runs, at its own interval on the tree's clock, between ticks. It returns
nothing and never changes the flow of the tree: it writes blackboard keys, so the conditions
below the composite stay plain comparisons of keys (``battery_percent < 20``) instead of
questions to the robot. They are Unreal Engine's behaviour-tree services, on behavior3 trees.

Write one by subclassing :class:`Service` and registering it::

    from cyborg.bt import Service, ServiceBoard, register_service

    @register_service("BatteryWatch")      # the name used in the editor; default: class name
    class BatteryWatch(Service):
        interval = 1.0                     # this service's default interval, in seconds

        def __init__(self, key: str = "battery") -> None:   # its options, as for nodes
            self.key = key

        def run(self, blackboard: ServiceBoard) -> None:
            robot = blackboard.resources["robot"]
            blackboard[f"{self.key}_percent"] = robot.battery.charge_percent

and declare it on a composite in behavior3editor, in the composite's ``services`` property
(the syntax is :mod:`cyborg.bt.service_syntax`'s)::

    services = "BatteryWatch(key=battery, interval=2); ClosestGoal"

**Lifecycle** (:mod:`cyborg.bt.service_runner` runs it): a service is *activated* when its
composite becomes RUNNING (at the end of the tick in which it returned RUNNING from idle), runs
every ``interval`` seconds while the composite stays RUNNING, and is *deactivated* exactly once
when the composite's activation ends: it returned SUCCESS or FAILURE, or it was halted (by its
parent, by the tree's halt or stop, or by a reload). A composite that completes in the tick it
started never activates its services. The three methods to override:

* :meth:`Service.on_activate` once when the composite becomes RUNNING;
* :meth:`Service.run` at each interval while it stays RUNNING (and once at activation with
  ``run_on_activation``);
* :meth:`Service.on_deactivate` once when the activation ends; it follows every
  ``on_activate``, even one that raised.

All three run on the thread that ticks the tree, never during a tick, so they may read and
write the blackboard without locks. They must be quick: fetch a value, compute, write. A
method that raises is logged with the composite's id, the service is deactivated (its
``on_deactivate`` runs) and stays stopped until the composite's next activation; the tree
goes on.

**Where they write.** Every method gets a :class:`ServiceBoard`, a view of the tree's
blackboard that reads and writes its *global* scope and records each write, so monitors show
what each service wrote. The global scope, not the composite's tree scope, because the
conditions that read the keys may sit in a subtree below the composite (a subtree instance has
a tree scope of its own) or in another mode's tree.

**Common options.** Every service takes four options in its declaration, beside its own:

* ``interval`` — seconds between runs (default: the class's :attr:`Service.interval`), at
  least :data:`MIN_INTERVAL`;
* ``deviation`` — a random ± seconds added to each interval (default: the class's
  :attr:`Service.deviation`); ``interval - deviation`` must be at least :data:`MIN_INTERVAL`;
* ``restart_on_activation`` — restart the timer each time the composite becomes active
  (default true); when false, the next due time is kept across activations, so a service
  whose composite becomes RUNNING again after its due time has passed runs at once;
* ``run_on_activation`` — also run once at activation, right after :meth:`on_activate`
  (default false).

Each interval drawn with a deviation is uniform in ``[interval - deviation, interval +
deviation]``, from a :class:`random.Random` of the service's own, seeded with the composite's
id and the service's position in the declaration: a tree runs its services at the same times
in every run, and two services never share a stream.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, ClassVar

from cyborg.bt.problems import shown

if TYPE_CHECKING:
    from cyborg.bt.blackboard import Blackboard

MIN_INTERVAL = 0.001
"""The shortest time between two runs of a service, in seconds: an ``interval`` less its
``deviation`` must leave at least this much, so a loop running due services always moves on."""

SHOWN_VALUE_LENGTH = 60
"""Characters at most of a written value as a monitor shows it (``wrote``)."""


@dataclass(frozen=True)
class ServiceTiming:
    """When one service runs: the four common options, resolved for one declaration."""

    interval: float
    """Seconds between runs, on the tree's clock."""
    deviation: float = 0.0
    """Random ± seconds added to each interval."""
    restart_on_activation: bool = True
    """Whether each activation restarts the timer (else the next due time carries over)."""
    run_on_activation: bool = False
    """Whether the service also runs once when its composite becomes RUNNING."""

    def to_json(self) -> dict[str, Any]:
        """The four options by their declaration names."""
        return {"interval": self.interval, "deviation": self.deviation,
                "restart_on_activation": self.restart_on_activation,
                "run_on_activation": self.run_on_activation}


class Service:
    """Base class of every service; see the module docstring for how to write one.

    The class attributes below are the service's defaults for the common options; a
    declaration overrides them per composite. The options of the service itself are the
    keyword parameters of its ``__init__``, type-checked as node properties are
    (:mod:`cyborg.bt.properties`). The engine binds :attr:`name`, :attr:`composite_uid` and
    :attr:`timing` after construction, so ``__init__`` need not call ``super().__init__()``.
    """

    interval: ClassVar[float] = 0.5
    """Default seconds between runs (Unreal's default)."""
    deviation: ClassVar[float] = 0.0
    """Default random ± seconds on each interval."""
    restart_on_activation: ClassVar[bool] = True
    """Default of the ``restart_on_activation`` option."""
    run_on_activation: ClassVar[bool] = False
    """Default of the ``run_on_activation`` option."""
    requires: ClassVar[tuple[str, ...]] = ()
    """Keys of the blackboard's resources the service cannot work without (``"robot"``)."""

    name: str = ""
    """The name it is registered and declared under."""
    composite_uid: str = ""
    """The stable id of the composite it is attached to."""
    timing: ServiceTiming
    """Its resolved common options."""

    def on_activate(self, blackboard: ServiceBoard) -> None:
        """Called once when the composite becomes RUNNING, before any :meth:`run`."""

    def run(self, blackboard: ServiceBoard) -> None:
        """Does the periodic work: read the world, write blackboard keys. Override it."""
        raise NotImplementedError(f"{type(self).__name__} does not implement run()")

    def on_deactivate(self, blackboard: ServiceBoard) -> None:
        """Called once when the composite's activation ends (finished or halted)."""

    def __repr__(self) -> str:
        return f"<{type(self).__name__} {self.name!r} on {self.composite_uid!r}>"


class ServiceBoard:
    """The blackboard as a service sees it: the global scope, with each write recorded.

    ``board[key]``, ``board.get(key)`` and ``key in board`` read the global scope;
    ``board[key] = value`` writes it and ``del board[key]`` removes a key. :attr:`now` is the
    time of the current call on the tree's clock, :attr:`resources` the handles the tree was
    given (``"robot"``).
    """

    __slots__ = ("_globals", "_wrote", "changed", "now", "resources")

    def __init__(self, blackboard: Blackboard) -> None:
        self._globals = blackboard.globals
        self.resources: dict[str, Any] = blackboard.resources
        """Handles to the outside world (``"robot"``), as nodes have them."""
        self.now = 0.0
        """Time of the current call, in seconds of the tree's clock."""
        self._wrote: dict[str, str] = {}
        self.changed = False
        """Set by each write; the runner clears it when it has taken note."""

    def __getitem__(self, key: str) -> Any:
        return self._globals[key]

    def get(self, key: str, default: Any = None) -> Any:
        """The global value of ``key``; ``default`` when it is not set."""
        return self._globals.get(key, default)

    def __contains__(self, key: object) -> bool:
        return key in self._globals

    def __iter__(self) -> Iterator[str]:
        return iter(self._globals)

    def __setitem__(self, key: str, value: Any) -> None:
        self._globals[key] = value
        text = shown(value)
        self._wrote[key] = text if len(text) <= SHOWN_VALUE_LENGTH \
            else text[:SHOWN_VALUE_LENGTH - 3] + "..."
        self.changed = True

    def __delitem__(self, key: str) -> None:
        self._globals.pop(key, None)
        self._wrote[key] = "(deleted)"
        self.changed = True

    @property
    def wrote(self) -> dict[str, str]:
        """Each key this service has written, with its last value as short text."""
        return dict(self._wrote)
