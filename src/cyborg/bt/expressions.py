"""Expressions of behavior3 v1's ``expr``/``code`` args: a small, safe, JavaScript-like language.

behavior3-ts evaluates args such as Check's ``value`` (``"hp > 50"``) or Calculate's
(``"(idx + dir + 8) % 8"``) against the tree's blackboard. :class:`Expression` does the same
without ever handing text to Python's ``eval``: the text is split into tokens, parsed once into
a tiny syntax tree (:class:`Literal`, :class:`Name`, :class:`Member`, :class:`Unary`,
:class:`Binary`, :class:`Conditional`), and that tree is walked against a mapping of
variables each time the expression is evaluated::

    check = Expression("target.hp > 0 && dist < 2.5")     # parse errors raise here, at load
    check.evaluate({"target": {"hp": 3}, "dist": 1.0})    # -> True

The language, by precedence from loosest to tightest::

    a ? b : c                 conditional (right to left)
    ||  &&                    logical; they return an operand and short-circuit, as in JS
    |  ^  &                   bitwise on 32-bit integers
    ==  !=  ===  !==          strict equality (behavior3-ts's == is JavaScript's ===)
    <  <=  >  >=              two numbers, or two strings
    <<  >>  >>>               shifts on 32-bit integers
    +  -                      numbers; + also joins a string with a string, number or boolean
    *  /  %                   numbers; / and % by zero give Infinity/NaN as in JavaScript
    !  ~  -  +                prefix operators
    a.b  a[i]  ( )            member access, grouping

Operands are numbers (``3``, ``2.5``, ``1e3``), strings (``'s'``, ``"s"``, with backslash
escapes), ``true``/``false``, ``null``/``undefined`` (both ``None``), ``NaN``, ``Infinity`` and
identifiers, which name blackboard variables (an unset one is ``undefined``). ``a.b`` and
``a[k]`` read a dict's key, a list's element (``undefined`` past its end) or ``length``.
Values follow JavaScript's rules (:mod:`cyborg.bt.js_values`): an empty list is true, and
numbers are doubles, as behavior3's runtimes have them: an integer past 2**53 becomes the
nearest double and one past the largest ``Infinity``, so ``n * n`` ticked over and over stays
one machine number. Digits are ASCII (``٣`` is no number). A text an expression makes holds at
most :data:`MAX_TEXT` characters.

Mixing kinds where JavaScript would silently coerce (``undefined > 3``, ``[1] + 1``) raises
:class:`ExpressionError` naming the operand instead. Text longer than :data:`MAX_LENGTH`
characters or nested deeper than :data:`MAX_DEPTH` levels is refused when parsed, so a hostile
expression can neither hang the parser nor exhaust the stack.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Mapping
from typing import Any, NamedTuple, NoReturn

from cyborg.bt.expression_tree import Binary, Conditional, Expr, Literal, Member, Name, Unary
from cyborg.bt.js_values import (
    ARITHMETIC,
    ORDER,
    describe,
    int32,
    js_number,
    js_text,
    read_member,
    strict_equal,
    truthy,
)
from cyborg.bt.limits import MAX_VALUE_SIZE
from cyborg.bt.status import NodeError

MAX_LENGTH = 1000
"""Longest expression text accepted, in characters."""
MAX_DEPTH = 50
"""Deepest nesting accepted: parentheses, operators applied to operators, member chains."""
MAX_TEXT = MAX_VALUE_SIZE
"""Longest text an expression makes, in characters: ``s + s`` ticked over and over doubles."""

_TOKEN = re.compile(r"""
    (?P<space>\s+)
  | (?P<number>[0-9]+(?:\.[0-9]+)?(?:[eE][+-]?[0-9]+)?)
  | (?P<name>[A-Za-z_$][A-Za-z0-9_$]*)
  | (?P<string>['"])
  | (?P<op>===|!==|>>>|<<|>>|<=|>=|==|!=|&&|\|\||[-+*/%<>!~&|^?:.\[\]()])
""", re.VERBOSE)
_KEYWORDS: dict[str, Any] = {"true": True, "false": False, "null": None, "undefined": None,
                             "NaN": math.nan, "Infinity": math.inf}
_ESCAPES = {"n": "\n", "t": "\t", "r": "\r", "0": "\0", "b": "\b", "f": "\f", "v": "\v"}
_BINARY: dict[str, int] = {
    "||": 3, "&&": 4, "|": 5, "^": 6, "&": 7, "==": 8, "!=": 8, "===": 8, "!==": 8,
    "<": 9, "<=": 9, ">": 9, ">=": 9, "<<": 10, ">>": 10, ">>>": 10,
    "+": 11, "-": 11, "*": 12, "/": 12, "%": 12}
"""Binding power of each infix operator (higher binds tighter), as in JavaScript."""
_PREFIX_POWER = 13
_POSTFIX_POWER = 15


class ExpressionError(NodeError, ValueError):
    """An expression that cannot be parsed, or whose operands do not fit its operators.

    The message quotes the expression and, where it helps, the part of it at fault.
    """


class _Token(NamedTuple):
    kind: str  # number, string, name, op, end
    value: Any
    start: int
    end: int


# ---------------------------------------------------------------------------- parsing
class Expression:
    """A parsed expression, ready to evaluate against any mapping of variables."""

    __slots__ = ("source", "tree")

    def __init__(self, source: str) -> None:
        if not isinstance(source, str):
            raise ExpressionError(f"an expression must be text, not {source!r}")
        if len(source) > MAX_LENGTH:
            raise ExpressionError(f"expression is {len(source)} characters long; at most "
                                  f"{MAX_LENGTH} are accepted")
        if not source.strip():
            raise ExpressionError("the expression is empty")
        self.source = source
        self.tree: Expr = _Parser(source).parse()

    def evaluate(self, variables: Mapping[str, Any]) -> Any:
        """The expression's value with ``variables`` (the blackboard) as its identifiers."""
        return _Evaluator(self.source, variables).value(self.tree)

    def __repr__(self) -> str:
        return f"Expression({self.source!r})"


def _tokens(source: str) -> list[_Token]:
    tokens: list[_Token] = []
    position = 0
    while position < len(source):
        match = _TOKEN.match(source, position)
        if match is None and source[position] == "=":
            raise ExpressionError(f"in {source!r}: '=' at column {position + 1} would assign; "
                                  "compare with '=='")
        if match is None:
            raise ExpressionError(f"in {source!r}: unexpected character "
                                  f"{source[position]!r} at column {position + 1}")
        kind = match.lastgroup or ""
        if kind == "string":
            text, end = _string(source, position)
            tokens.append(_Token("string", text, position, end))
            position = end
            continue
        end = match.end()
        if kind == "number":
            if end < len(source) and (source[end].isalnum() or source[end] in "_$"):
                word = re.match(r"[\w$]+", source[position:])
                raise ExpressionError(f"in {source!r}: {word.group() if word else ''!r} at "
                                      f"column {position + 1} is neither a number nor a name")
            text = match.group()
            number = float(text) if any(c in text for c in ".eE") else js_number(int(text))
            tokens.append(_Token("number", number, position, end))
        elif kind in ("name", "op"):
            tokens.append(_Token(kind, match.group(), position, end))
        position = end
    tokens.append(_Token("end", None, len(source), len(source)))
    return tokens


def _string(source: str, start: int) -> tuple[str, int]:
    quote, position = source[start], start + 1
    chars: list[str] = []
    while position < len(source):
        char = source[position]
        if char == quote:
            return "".join(chars), position + 1
        if char == "\\" and position + 1 < len(source):
            position += 1
            char = _ESCAPES.get(source[position], source[position])
        chars.append(char)
        position += 1
    raise ExpressionError(f"in {source!r}: the string starting at column {start + 1} is "
                          f"not closed with {quote}")


class _Parser:
    """Pratt parser: each operator's binding power decides how far its operand reaches."""

    def __init__(self, source: str) -> None:
        self.source = source
        self.tokens = _tokens(source)
        self.index = 0
        self.nesting = 0

    def parse(self) -> Expr:
        tree = self.expression(0)
        token = self.peek()
        if token.kind != "end":
            self.fail(f"unexpected {self.describe(token)} (an operator missing?)", token)
        return tree

    def peek(self) -> _Token:
        return self.tokens[self.index]

    def take(self) -> _Token:
        token = self.tokens[self.index]
        self.index += 1
        return token

    def expect(self, op: str) -> _Token:
        token = self.take()
        if token.kind != "op" or token.value != op:
            self.fail(f"expected {op!r} but found {self.describe(token)}", token)
        return token

    def fail(self, message: str, token: _Token) -> NoReturn:
        raise ExpressionError(f"in {self.source!r}: {message} at column {token.start + 1}")

    @staticmethod
    def describe(token: _Token) -> str:
        if token.kind == "end":
            return "the end"
        return "a string" if token.kind == "string" else repr(token.value)

    def expression(self, power: int) -> Expr:
        """Everything up to the first operator that binds no tighter than ``power``."""
        self.nesting += 1
        if self.nesting > MAX_DEPTH:
            self.fail(f"nested more than {MAX_DEPTH} levels deep", self.peek())
        left = self.prefix()
        while True:
            token = self.peek()
            if token.kind != "op":
                break
            op = token.value
            if op in (".", "[") and power < _POSTFIX_POWER:
                left = self.member(left)
            elif op == "?" and power < 2:
                self.take()
                then = self.expression(0)
                self.expect(":")
                otherwise = self.expression(1)  # right to left: a ? b : c ? d : e
                left = self.node(Conditional, left.start, otherwise.end, left, then, otherwise)
            elif op in _BINARY and _BINARY[op] > power:
                self.take()
                right = self.expression(_BINARY[op])
                left = self.node(Binary, left.start, right.end, op, left, right)
            else:
                break
        self.nesting -= 1
        return left

    def prefix(self) -> Expr:
        token = self.take()
        if token.kind in ("number", "string"):
            return Literal(token.start, token.end, 1, token.value)
        if token.kind == "name":
            if token.value in _KEYWORDS:
                return Literal(token.start, token.end, 1, _KEYWORDS[token.value])
            return Name(token.start, token.end, 1, token.value)
        if token.kind == "op" and token.value == "(":
            inner = self.expression(0)
            self.expect(")")
            return inner
        if token.kind == "op" and token.value in ("!", "~", "-", "+"):
            operand = self.expression(_PREFIX_POWER)
            return self.node(Unary, token.start, operand.end, token.value, operand)
        self.fail(f"expected a value but found {self.describe(token)}", token)

    def member(self, target: Expr) -> Expr:
        token = self.take()
        if token.value == ".":
            name = self.take()
            if name.kind != "name":
                self.fail(f"expected a field name after '.' but found {self.describe(name)}",
                          name)
            key: Expr = Literal(name.start, name.end, 1, name.value)
            end = name.end
        else:
            key = self.expression(0)
            end = self.expect("]").end
        return self.node(Member, target.start, end, target, key)

    def node(self, kind: Callable[..., Expr], start: int, end: int, *parts: Any) -> Expr:
        depth = 1 + max(part.depth for part in parts if isinstance(part, Expr))
        if depth > MAX_DEPTH:
            raise ExpressionError(f"in {self.source!r}: nested more than {MAX_DEPTH} levels "
                                  f"deep (column {start + 1})")
        return kind(start, end, depth, *parts)


# ---------------------------------------------------------------------------- evaluation
class _Evaluator:
    def __init__(self, source: str, variables: Mapping[str, Any]) -> None:
        self.source = source
        self.variables = variables

    def fail(self, message: str) -> ExpressionError:
        return ExpressionError(f"in {self.source!r}: {message}")

    def text(self, node: Expr) -> str:
        return repr(self.source[node.start:node.end].strip())

    def shown(self, node: Expr, value: Any) -> str:
        """``'hp' (undefined)``: an operand's text and what it held."""
        kind = describe(value)
        return kind if isinstance(node, Literal) else f"{self.text(node)} ({kind})"

    def value(self, node: Expr) -> Any:
        if isinstance(node, Literal):
            return node.value
        if isinstance(node, Name):
            return self.variables.get(node.name)
        if isinstance(node, Member):
            return self.member(node)
        if isinstance(node, Conditional):
            chosen = node.then if truthy(self.value(node.test)) else node.otherwise
            return self.value(chosen)
        if isinstance(node, Unary):
            return self.unary(node)
        assert isinstance(node, Binary)
        return self.binary(node)

    def number(self, node: Expr, value: Any, op: str) -> float:
        if isinstance(value, int | float):
            return int(value) if type(value) is bool else js_number(value)
        raise self.fail(f"{op!r} needs a number, but {self.shown(node, value)} is not one")

    def unary(self, node: Unary) -> Any:
        value = self.value(node.operand)
        if node.op == "!":
            return not truthy(value)
        number = self.number(node.operand, value, node.op)
        if node.op == "-":
            return -number
        return ~int32(number) if node.op == "~" else number

    def binary(self, node: Binary) -> Any:
        op, left = node.op, self.value(node.left)
        if op in ("&&", "||"):  # short-circuit: the right side only when it decides
            return left if truthy(left) == (op == "||") else self.value(node.right)
        right = self.value(node.right)
        if op in ("==", "==="):
            return strict_equal(left, right)
        if op in ("!=", "!=="):
            return not strict_equal(left, right)
        if op in ORDER:
            if isinstance(left, str) and isinstance(right, str):
                return ORDER[op](left, right)
            if not (isinstance(left, str) or isinstance(right, str)):
                a, b = self.number(node.left, left, op), self.number(node.right, right, op)
                return ORDER[op](a, b)
            raise self.fail(f"{op!r} compares two numbers or two strings, not "
                            f"{self.shown(node.left, left)} and {self.shown(node.right, right)}")
        if op == "+" and (isinstance(left, str) or isinstance(right, str)):
            for side, value in ((node.left, left), (node.right, right)):
                if not isinstance(value, str | int | float):
                    raise self.fail(f"'+' joins a string only with a string, number or "
                                    f"boolean, not {self.shown(side, value)}")
            return self.joined(node, js_text(left), js_text(right))
        a, b = self.number(node.left, left, op), self.number(node.right, right, op)
        try:
            return js_number(a + b if op == "+" else ARITHMETIC[op](a, b))
        except OverflowError:
            raise self.fail(f"{op!r}: the result of {self.text(node)} is too large") from None

    def joined(self, node: Binary, left: str, right: str) -> str:
        if len(left) + len(right) > MAX_TEXT:
            raise self.fail(f"'+': the result of {self.text(node)} would be "
                            f"{len(left) + len(right):,} characters, more than the "
                            f"{MAX_TEXT:,} a text may hold")
        return left + right

    def member(self, node: Member) -> Any:
        target = self.value(node.target)
        key = self.value(node.key)
        try:
            return read_member(target, key)
        except TypeError:
            field = key if isinstance(key, str) else js_text(key)
            raise self.fail(f"cannot read {field!r} of {self.shown(node.target, target)}: only "
                            "objects, lists and strings have fields") from None
