"""From a composite's ``services`` property to live services, checked at load.

The builder hands each composite's declaration here (:func:`attach_services`). The text is
parsed (:mod:`cyborg.bt.service_syntax`), each name is looked up in the
:class:`~cyborg.bt.service_registry.ServiceRegistry`, the common options (``interval``,
``deviation``, ``restart_on_activation``, ``run_on_activation``) are taken out and checked,
and the remaining options are checked against the service class's ``__init__`` as node
properties are (:func:`cyborg.bt.properties.bind`; ``camelCase`` and ``snake_case`` both
work). Every problem names the column of the property's text it is about; an unknown name or
option comes with the closest known ones (``period`` is answered with ``interval``).

A ``services`` property on a node that is not a composite is an error, unless the node's own
class takes a ``services`` parameter (then it is that node's property, as any other).
"""

from __future__ import annotations

import difflib
import math
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

from cyborg.bt.node import Category, Node
from cyborg.bt.problems import shown
from cyborg.bt.properties import bind, convert, signature_of, snake_case
from cyborg.bt.service_runner import ScheduledService
from cyborg.bt.service_syntax import ServiceCall, ServiceSyntaxError, parse_services
from cyborg.bt.services import MIN_INTERVAL, Service, ServiceTiming

if TYPE_CHECKING:
    from cyborg.bt.blackboard import Blackboard
    from cyborg.bt.service_registry import ServiceRegistry, ServiceType

SERVICES = "services"
"""The name of the property that declares a composite's services."""

COMMON_OPTIONS = ("interval", "deviation", "restart_on_activation", "run_on_activation")
"""The options every service takes beside its own (see :mod:`cyborg.bt.services`)."""

ALIASES = {"period": "interval", "rate": "interval", "every": "interval",
           "random_deviation": "deviation", "jitter": "deviation",
           "restart_timer": "restart_on_activation", "call_on_start": "run_on_activation",
           "run_on_start": "run_on_activation", "tick_on_search_start": "run_on_activation"}
"""Names users bring from elsewhere, answered with the one cyborg uses (snake_case)."""


def owns_services(cls: type[Node]) -> bool:
    """Whether the node class takes a ``services`` parameter of its own."""
    return any(param.name == SERVICES for param in signature_of(cls).params)


def without_services(cls: type[Node], properties: dict[str, Any]) -> dict[str, Any]:
    """``properties`` less the services declaration, for binding to the node's class."""
    if SERVICES not in properties or owns_services(cls):
        return properties
    return {key: value for key, value in properties.items() if key != SERVICES}


def attach_services(declaration: Any, composite: Node, registry: ServiceRegistry,
                    blackboard: Blackboard) -> tuple[list[ScheduledService], list[str]]:
    """The services ``declaration`` attaches to ``composite``, and the problems found.

    With any problem, no service is returned: nothing of a bad declaration runs.
    """
    if composite.category is not Category.COMPOSITE:
        category = composite.category.value
        article = "an" if category[0] in "aeiou" else "a"
        return [], [f"services attach to composites only (Sequence, Priority, Parallel, ...); "
                    f"{composite.name} is {article} {category}: move the property to the "
                    "composite above it"]
    if not isinstance(declaration, str):
        return [], [f"the services property is text such as \"BatteryWatch(interval=1.0); "
                    f"ClosestGoal\", not {shown(declaration)}"]
    try:
        calls = parse_services(declaration)
    except ServiceSyntaxError as exc:
        return [], [f"services, {exc}"]
    attached: list[ScheduledService] = []
    problems: list[str] = []
    for position, call in enumerate(calls):
        service_type = registry.get(call.name)
        if service_type is None:
            problems.append(_at(call.column, _unknown_service(call.name, registry)))
            continue
        made = _make(call, service_type, composite, problems)
        if made is not None:
            attached.append(ScheduledService(made, composite, blackboard, position, call.text))
    return ([] if problems else attached), problems


def without_unprovided(attached: list[ScheduledService], resources: dict[str, Any]
                       ) -> tuple[list[ScheduledService], list[str]]:
    """The services whose required resources are all there, and a warning for each other.

    For a tree loaded with stubs for what it lacks (``stub_missing``): a service that needs
    the robot is left out of a tree that has none, as a node that needs it is stubbed.
    """
    kept: list[ScheduledService] = []
    warnings: list[str] = []
    for scheduled in attached:
        absent = [key for key in scheduled.service.requires if key not in resources]
        if absent:
            warnings.append(f"service {scheduled.service.name!r} needs a {absent[0]!r} resource "
                            "and this tree has none; it is left out")
        else:
            kept.append(scheduled)
    return kept, warnings


def _make(call: ServiceCall, service_type: ServiceType, composite: Node,
          problems: list[str]) -> Service | None:
    """The service of one call, bound; ``None`` after adding its problems."""
    cls = service_type.cls
    common: dict[str, Any] = {}
    own: dict[str, Any] = {}
    for key, value in call.options.items():
        if snake_case(key) in COMMON_OPTIONS:
            common[snake_case(key)] = value
        else:
            own[key] = value
    count = len(problems)
    timing = _timing(call, cls, common, problems)
    binding = bind(service_type.signature, own)
    known = [*COMMON_OPTIONS, *(param.name for param in service_type.signature.params)]
    for key, _message in binding.warnings:  # an unknown option is an error for a service
        problems.append(_at(call.option_columns.get(key, call.column),
                            _unknown_option(key, call.name, known)))
    for key, message in binding.errors:
        problems.append(_at(call.option_columns.get(key, call.column),
                            f"{call.name}: {message.replace('property', 'option')}"))
    if len(problems) > count or timing is None:
        return None
    try:
        service = cls(**binding.kwargs)
    except Exception as exc:
        problems.append(_at(call.column, f"{call.text} raised {type(exc).__name__}: {exc}"))
        return None
    service.name = call.name
    service.composite_uid = composite.uid
    service.timing = timing
    return service


def _timing(call: ServiceCall, cls: type[Service], common: dict[str, Any],
            problems: list[str]) -> ServiceTiming | None:
    """The common options of one call, checked; ``None`` after adding its problems."""
    values: dict[str, Any] = {"interval": cls.interval, "deviation": cls.deviation,
                              "restart_on_activation": cls.restart_on_activation,
                              "run_on_activation": cls.run_on_activation}
    count = len(problems)
    for name, value in common.items():
        column = next((c for key, c in call.option_columns.items() if snake_case(key) == name),
                      call.column)
        try:
            values[name] = convert(value, bool if name.endswith("activation") else float)
        except ValueError as exc:
            problems.append(_at(column, f"{call.name}: option {name!r}: {exc}"))
    interval, deviation = values["interval"], values["deviation"]
    if len(problems) == count:
        if not (isinstance(interval, float | int) and math.isfinite(interval)
                and interval >= MIN_INTERVAL):
            problems.append(_at(call.column, f"{call.name}: interval must be a number of "
                                             f"seconds, at least {MIN_INTERVAL}, not "
                                             f"{shown(interval)}"))
        elif not 0 <= deviation <= interval - MIN_INTERVAL:
            problems.append(_at(call.column, f"{call.name}: deviation must be at least 0 and "
                                             f"leave at least {MIN_INTERVAL} s of the interval "
                                             f"({interval} s), not {shown(deviation)}"))
    if len(problems) > count:
        return None
    return ServiceTiming(float(interval), float(deviation),
                         bool(values["restart_on_activation"]), bool(values["run_on_activation"]))


def _at(column: int, message: str) -> str:
    return message if message.startswith("services, column") \
        else f"services, column {column}: {message}"


def _unknown_service(name: str, registry: ServiceRegistry) -> str:
    names = registry.names()
    close = difflib.get_close_matches(name, names, n=3, cutoff=0.6)
    hint = f"; did you mean {_either(close)}?" if close else ""
    listed = ", ".join(names) if names else "none"
    return f"unknown service {name!r}{hint} (registered: {listed})"


def _unknown_option(key: str, service: str, known: Sequence[str]) -> str:
    alias = ALIASES.get(snake_case(key))
    close = [alias] if alias else difflib.get_close_matches(snake_case(key), known, n=3,
                                                            cutoff=0.6)
    hint = f"; did you mean {_either(close)}?" if close else ""
    return f"{service} has no option {key!r}{hint} (options: {', '.join(known)})"


def _either(names: Sequence[str]) -> str:
    quoted = [repr(name) for name in names]
    return quoted[0] if len(quoted) == 1 else ", ".join(quoted[:-1]) + " or " + quoted[-1]
