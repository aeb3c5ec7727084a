"""Per-subscriber copies of a message that share its arrays read-only.

In-process delivery hands one published message to many subscribers without serialising it.
Each subscriber gets its own message objects (setting an attribute changes nothing for the
others), while numpy arrays — the bulk of an image — are shared as read-only views: writing to
one raises ``ValueError: assignment destination is read-only`` instead of corrupting what the
other subscribers see. Nothing of the payload is copied.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from rosbags.interfaces import Nodetype

from cyborg.bus.message_types import MessageTypes

_NESTED, _NESTED_LIST, _VALUES = 1, 2, 3
Plan = list[tuple[str, int, str]]


class ReadonlyCopier:
    """Makes read-only sharing copies for the types of one :class:`MessageTypes`."""

    def __init__(self, types: MessageTypes) -> None:
        self._types = types
        self._plans: dict[str, Plan] = {}

    def copy(self, message: Any, type_name: str) -> Any:
        """A copy of ``message`` (of ``type_name``) for one subscriber; see the module doc."""
        plan = self._plans.get(type_name)
        if plan is None:
            plan = self._plans[type_name] = self._plan(type_name)
        fresh = object.__new__(type(message))
        fresh.__dict__.update(message.__dict__)
        for name, how, nested in plan:
            value = getattr(message, name)
            if how == _NESTED:
                setattr(fresh, name, self.copy(value, nested))
            elif how == _NESTED_LIST:
                setattr(fresh, name, [self.copy(item, nested) for item in value])
            elif isinstance(value, np.ndarray):
                view = value.view()
                view.flags.writeable = False
                setattr(fresh, name, view)
            else:
                setattr(fresh, name, list(value))
        return fresh

    def _plan(self, type_name: str) -> Plan:
        plan: Plan = []
        fields: list[tuple[str, tuple[Any, Any]]] = self._types.store.fielddefs[type_name][1]
        for name, (kind, spec) in fields:
            if kind == Nodetype.NAME:
                plan.append((name, _NESTED, spec))
            elif kind in (Nodetype.ARRAY, Nodetype.SEQUENCE):
                (element_kind, element), _bound = spec
                if element_kind == Nodetype.NAME:
                    plan.append((name, _NESTED_LIST, element))
                else:
                    plan.append((name, _VALUES, ""))
        return plan
