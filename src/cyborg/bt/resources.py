"""Which resources a node class needs: those it declares, and those its code fetches.

A node that cannot work without a handle in :attr:`Blackboard.resources
<cyborg.bt.blackboard.Blackboard.resources>` (the robot) says so in its
:attr:`~cyborg.bt.node.Node.requires`, and a tree without that resource is refused before its
first tick (or given stubs, ``--stub-missing``). A node written in a hurry often does not
declare it and fetches the handle all the same, with the function its package gives for that
(``robot_of(self)``). Such functions are marked with :func:`fetches_resource`, and
:func:`requirements_of` finds the classes whose methods call one: they need the resource as
if they had declared it, so they are found before the first tick too, not by an exception in
it.

The calls are found in the methods' compiled code (the global or attribute names they use,
nested functions included), in the class and its bases outside this package; a method that
calls the function only now and then counts as needing it.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable, Iterator
from types import CodeType
from typing import Any, TypeVar

F = TypeVar("F", bound=Callable[..., Any])

_FETCHERS: dict[str, str] = {}
"""The name of each function marked by :func:`fetches_resource` -> the resource it fetches."""
_FOUND: dict[tuple[type, int], tuple[str, ...]] = {}
"""What :func:`requirements_of` found per class, while the fetchers known stay the same."""


def fetches_resource(key: str) -> Callable[[F], F]:
    """Marks a function that fetches the resource ``key`` for a node (``robot_of``).

    A node class whose methods call it needs ``key`` (:func:`requirements_of`).
    """
    def mark(function: F) -> F:
        _FETCHERS[function.__name__] = key
        return function
    return mark


def requirements_of(cls: type) -> tuple[str, ...]:
    """The resource keys ``cls`` needs: its ``requires``, then those its methods fetch."""
    declared: tuple[str, ...] = tuple(getattr(cls, "requires", ()))
    cached = _FOUND.get((cls, len(_FETCHERS)))
    if cached is None:
        names = {name for code in _codes(cls) for name in _names(code)}
        cached = tuple(dict.fromkeys(key for name, key in _FETCHERS.items() if name in names))
        _FOUND[(cls, len(_FETCHERS))] = cached
    return tuple(dict.fromkeys((*declared, *cached)))


def _codes(cls: type) -> Iterator[CodeType]:
    """The code of every function ``cls`` and its bases (outside this package) define."""
    for base in inspect.getmro(cls):
        if base.__module__.startswith("cyborg.bt.") or base is object:
            continue
        for value in vars(base).values():
            if isinstance(value, (staticmethod, classmethod)):
                value = value.__func__
            elif isinstance(value, property):
                value = value.fget
            code = getattr(value, "__code__", None)
            if isinstance(code, CodeType):
                yield code


def _names(code: CodeType) -> Iterator[str]:
    """The global and attribute names ``code`` and the functions nested in it use."""
    yield from code.co_names
    for constant in code.co_consts:
        if isinstance(constant, CodeType):
            yield from _names(constant)
