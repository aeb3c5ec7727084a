"""What the node and service registries share: a table of named entries, filled by entry points.

A :class:`NamedRegistry` maps the names a tree file uses to entries (``NodeType`` in
:mod:`cyborg.bt.registry`, ``ServiceType`` in :mod:`cyborg.bt.service_registry`). Each
subclass says what kind of class it registers (:attr:`~NamedRegistry.kind`), how to make an
entry (its ``add``) and where its decorator collects classes (:meth:`NamedRegistry.registered`);
loading an entry-point group and copying the table are the same for both.
"""

from __future__ import annotations

import inspect
import logging
from importlib.metadata import EntryPoint, entry_points
from typing import ClassVar, Generic, Protocol, Self, TypeVar

OWN_DISTRIBUTION = "cyborg"
"""The distribution whose entry points (the robot's nodes and services) load first."""


class Entry(Protocol):
    """An entry of a registry: at least a name."""

    @property
    def name(self) -> str:
        """The name tree files use."""
        ...

    @property
    def cls(self) -> type:
        """The class registered under it."""
        ...

    @property
    def origin(self) -> str:
        """Where it came from: a module name, ``stock``, or ``entry point <name>``."""
        ...


class NameTakenError(ValueError):
    """A name registered for another class without ``override=True``; the message names both."""


def _same_class(a: type, b: type) -> bool:
    """Whether ``a`` and ``b`` are one class, perhaps of a module imported again."""
    return a is b or (a.__module__, a.__qualname__) == (b.__module__, b.__qualname__)


def describe(entry: Entry) -> str:
    """``my_robot.nodes.Say (from my_robot.nodes)``: the class and where it comes from."""
    cls = entry.cls
    return f"{cls.__module__}.{cls.__qualname__} (from {entry.origin})"


E = TypeVar("E", bound=Entry)


class NamedRegistry(Generic[E]):
    """Names to entries; see the module."""

    kind: ClassVar[type]
    """The class every registered class derives from (``Node``, ``Service``)."""

    def __init__(self) -> None:
        self._types: dict[str, E] = {}
        self._overridden: set[str] = set()
        """The names an ``override=True`` registration holds."""

    def add(self, cls: type, name: str | None = None, *, origin: str = "",
            override: bool = False) -> E:
        """Registers ``cls`` under ``name``; each registry checks and builds its own entry.

        It then enters it with :meth:`enter`.
        """
        raise NotImplementedError

    def enter(self, entry: E, *, override: bool = False) -> E:
        """Puts ``entry`` in the table under its name and returns what holds the name now.

        Another class under the same name is refused with :class:`NameTakenError` (naming both
        and where each comes from) unless ``override``; then the new one takes the name, and
        keeps it against later registrations that do not override (it is logged). The same
        class again (or its module imported again) just replaces its entry.
        """
        existing = self._types.get(entry.name)
        if existing is not None and not _same_class(existing.cls, entry.cls):
            kind = self.kind.__name__.lower()
            if not override:
                if entry.name in self._overridden:
                    return existing  # overridden on purpose, whichever was registered first
                raise NameTakenError(
                    f"{kind} name {entry.name!r} is taken by {describe(existing)}; "
                    f"{describe(entry)} would replace it: register it with override=True "
                    f"to replace it on purpose, or under another name")
            logging.getLogger("cyborg.bt").info(
                "%s %r: %s replaces %s (override=True)", kind, entry.name, describe(entry),
                describe(existing))
        if override:
            self._overridden.add(entry.name)
        self._types[entry.name] = entry
        return entry

    def registered(self) -> Self | None:
        """The registry its decorator fills, whose entries a loaded module may have added."""
        return None

    def get(self, name: str) -> E | None:
        """The entry registered under ``name``, or ``None``."""
        return self._types.get(name)

    def __contains__(self, name: object) -> bool:
        return name in self._types

    def names(self) -> list[str]:
        """All registered names, sorted."""
        return sorted(self._types)

    def copy(self) -> Self:
        """An independent registry with the same entries (for adding entries locally)."""
        other = type(self)()
        other._types = dict(self._types)
        other._overridden = set(self._overridden)
        return other

    def load_entry_points(self, group: str) -> list[str]:
        """Registers what every installed entry point of ``group`` names.

        An entry point names a module (importing it runs its decorators, whose classes are
        taken in too) or one class, registered under the entry's name. cyborg's own come first.
        Returns a message for each entry point that could not be loaded (or whose name is taken,
        :meth:`enter`); those are skipped.
        """
        kind = self.kind.__name__
        problems = []
        for entry in sorted(entry_points(group=group), key=_not_own):
            try:
                loaded = entry.load()
                if inspect.isclass(loaded) and issubclass(loaded, self.kind):
                    self.add(loaded, entry.name, origin=f"entry point {entry.name}")
                elif not inspect.ismodule(loaded):
                    problems.append(f"entry point {entry.name!r} ({entry.value}) is neither a "
                                    f"module nor a {kind} subclass")
            except Exception as exc:
                problems.append(f"entry point {entry.name!r} ({entry.value}): "
                                f"{type(exc).__name__}: {exc}")
        self.take_registered()
        return problems

    def take_registered(self) -> None:
        """Adds what the decorator registered since, keeping entries of the same name here.

        A name the decorator registered with ``override=True`` is taken from it all the same.
        """
        registered = self.registered()
        if registered is not None and registered is not self:
            self._types.update({key: value for key, value in registered._types.items()
                                if key not in self._types or key in registered._overridden})
            self._overridden |= registered._overridden


def _not_own(entry: EntryPoint) -> bool:
    """Sorts cyborg's own entry points first (False before True)."""
    return entry.dist is None or entry.dist.name != OWN_DISTRIBUTION
