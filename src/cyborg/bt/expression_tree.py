"""The syntax tree of an :class:`~cyborg.bt.expressions.Expression`.

One frozen node per construct, each knowing where its text stands in the expression (for
messages) and how deep it is nested (the parser refuses past ``MAX_DEPTH``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any


@dataclass(frozen=True, slots=True)
class Expr:
    """A node of the syntax tree; ``start``/``end`` locate its text (for messages)."""

    start: int
    end: int
    depth: int


@dataclass(frozen=True, slots=True)
class Literal(Expr):
    """A constant: a number, a string, or a keyword's value (``null`` is ``None``)."""

    value: Any


@dataclass(frozen=True, slots=True)
class Name(Expr):
    """An identifier: the variable ``name``, ``undefined`` (``None``) while it is unset."""

    name: str


@dataclass(frozen=True, slots=True)
class Member(Expr):
    """Member access, ``target.key`` or ``target[key]``: a key, element or ``length``."""

    target: Expr
    key: Expr
    """The key: a :class:`Literal` for ``a.b``, any expression for ``a[k]``."""


@dataclass(frozen=True, slots=True)
class Unary(Expr):
    """A prefix operator (``!``, ``~``, ``-`` or ``+``) applied to ``operand``."""

    op: str
    operand: Expr


@dataclass(frozen=True, slots=True)
class Binary(Expr):
    """An infix operator; for ``&&`` and ``||`` the right side is evaluated only if needed."""

    op: str
    left: Expr
    right: Expr


@dataclass(frozen=True, slots=True)
class Conditional(Expr):
    """``test ? then : otherwise``; only the branch chosen is evaluated."""

    test: Expr
    then: Expr
    otherwise: Expr
