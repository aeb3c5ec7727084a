"""What the node and service registries share: a table of named entries, filled by entry points.

A :class:`NamedRegistry` maps the names a tree file uses to entries (``NodeType`` in
:mod:`cyborg.bt.registry`, ``ServiceType`` in :mod:`cyborg.bt.service_registry`). Each
subclass says what kind of class it registers (:attr:`~NamedRegistry.kind`), how to make an
entry (its ``add``) and where its decorator collects classes (:meth:`NamedRegistry.registered`);
loading an entry-point group and copying the table are the same for both.
"""

from __future__ import annotations

import inspect
from importlib.metadata import entry_points
from typing import ClassVar, Generic, Protocol, Self, TypeVar


class Entry(Protocol):
    """An entry of a registry: at least a name."""

    @property
    def name(self) -> str:
        """The name tree files use."""
        ...


E = TypeVar("E", bound=Entry)


class NamedRegistry(Generic[E]):
    """Names to entries; see the module."""

    kind: ClassVar[type]
    """The class every registered class derives from (``Node``, ``Service``)."""

    def __init__(self) -> None:
        self._types: dict[str, E] = {}

    def add(self, cls: type, name: str | None = None, *, origin: str = "") -> E:
        """Registers ``cls`` under ``name``; each registry checks and builds its own entry."""
        raise NotImplementedError

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
        return other

    def load_entry_points(self, group: str) -> list[str]:
        """Registers what every installed entry point of ``group`` names.

        An entry point names a module (importing it runs its decorators, whose classes are
        taken in too) or one class, registered under the entry's name. Returns a message for
        each entry point that could not be loaded; those are skipped.
        """
        kind = self.kind.__name__
        problems = []
        for entry in entry_points(group=group):
            try:
                loaded = entry.load()
            except Exception as exc:
                problems.append(f"entry point {entry.name!r} ({entry.value}): "
                                f"{type(exc).__name__}: {exc}")
                continue
            if inspect.isclass(loaded) and issubclass(loaded, self.kind):
                self.add(loaded, entry.name, origin=f"entry point {entry.name}")
            elif not inspect.ismodule(loaded):
                problems.append(f"entry point {entry.name!r} ({entry.value}) is neither a "
                                f"module nor a {kind} subclass")
        self.take_registered()
        return problems

    def take_registered(self) -> None:
        """Adds what the decorator registered since, keeping entries of the same name here."""
        registered = self.registered()
        if registered is not None and registered is not self:
            self._types.update({key: value for key, value in registered._types.items()
                                if key not in self._types})
