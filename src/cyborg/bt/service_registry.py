"""The service registry: which Python class implements each service name in the editor.

Services are registered as nodes are (:mod:`cyborg.bt.registry`), in a registry of their own:

    @register_service("BatteryWatch")      # default: the class name
    class BatteryWatch(Service): ...

Another package adds services without being imported by hand, by declaring an entry point in
the group ``cyborg.services`` (in its ``pyproject.toml``)::

    [project.entry-points."cyborg.services"]
    my_services = "my_package.services"            # a module: its @register_service lines
    Watch = "my_package.services:Watch"            # or one class, under the entry's name

:func:`default_service_registry` holds everything registered with the decorator and every
entry point's services. A tree file names services only in composites' ``services``
property, so the registry is read only when a file declares one.
"""

from __future__ import annotations

import importlib
import inspect
import logging
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Any, TypeVar, overload

from cyborg.bt.named_registry import NamedRegistry
from cyborg.bt.properties import Signature, signature_of
from cyborg.bt.services import Service

SERVICE_ENTRY_POINT_GROUP = "cyborg.services"

S = TypeVar("S", bound=type[Service])


@dataclass(frozen=True)
class ServiceType:
    """A registered service: its editor name, implementing class and options."""

    name: str
    cls: type[Service]
    signature: Signature
    """Its own options, from its ``__init__``; the common options come beside them."""
    origin: str
    """Where it came from: a module name, or ``entry point <name>``."""


class ServiceRegistry(NamedRegistry[ServiceType]):
    """Maps editor service names to service classes."""

    kind = Service

    def add(self, cls: type, name: str | None = None, *, origin: str = "",
            override: bool = False) -> ServiceType:
        """Registers ``cls`` under ``name`` (default: the class name); returns what holds it.

        Raises :class:`TypeError` for a class that is not a :class:`Service`,
        :class:`ValueError` for a name that is not an identifier (a declaration could not
        name it), and :class:`~cyborg.bt.named_registry.NameTakenError` for a name another
        class has, unless ``override``.
        """
        if not (inspect.isclass(cls) and issubclass(cls, Service)):
            raise TypeError(f"{cls!r} is not a Service subclass")
        key = name if name is not None else cls.__name__
        if not key.isidentifier():
            raise ValueError(f"a service name is letters, digits and '_' (not starting with a "
                             f"digit), so a declaration can name it; not {key!r}")
        service_type = ServiceType(key, cls, signature_of(cls), origin or cls.__module__)
        return self.enter(service_type, override=override)

    def registered(self) -> ServiceRegistry:
        """Where :func:`register_service` puts services."""
        return _REGISTERED

    def load_entry_points(self, group: str = SERVICE_ENTRY_POINT_GROUP) -> list[str]:
        """Registers the services of every installed entry point in ``group`` (see the base)."""
        return super().load_entry_points(group)

    def import_modules(self, modules: Iterable[str]) -> None:
        """Imports modules whose ``@register_service`` lines add services.

        Raises :class:`ImportError` naming the first module that cannot be imported.
        """
        for module in modules:
            try:
                importlib.import_module(module)
            except Exception as exc:
                raise ImportError(f"cannot import service module {module!r}: "
                                  f"{type(exc).__name__}: {exc}") from exc
        self.take_registered()


_REGISTERED = ServiceRegistry()
"""Where :func:`register_service` puts services; :func:`default_service_registry` starts
from it."""


@overload
def register_service(name: S, /) -> S: ...
@overload
def register_service(name: str | None = None, /, *,
                     override: bool = False) -> Callable[[S], S]: ...
def register_service(name: Any = None, /, *, override: bool = False) -> Any:
    """Class decorator: makes a service available to declarations under ``name``.

    ``name`` defaults to the class name; ``@register_service`` works without parentheses too.
    A name another service has is refused unless ``override=True``, as for nodes.
    """
    if inspect.isclass(name) and issubclass(name, Service):
        _REGISTERED.add(name)
        return name

    def decorate(cls: S) -> S:
        _REGISTERED.add(cls, name, override=override)
        return cls

    return decorate


def default_service_registry(*, entry_points: bool = True) -> ServiceRegistry:
    """A new registry of every service a tree may declare.

    It holds every ``@register_service``-ed service and, with ``entry_points``, those of
    installed entry points (one that cannot be loaded is logged and skipped).
    """
    registry = _REGISTERED.copy()
    if entry_points:
        for problem in registry.load_entry_points():
            logging.getLogger("cyborg.bt").warning("skipping service %s", problem)
    return registry
