"""behavior3 v1's data nodes: expressions, variables, arrays and objects on the blackboard.

These are the stock actions and conditions of behavior3-ts (the runtime of behavior3editor
1.x), with its semantics. They pass data through blackboard variables that the tree file binds
to their ports by position (:mod:`cyborg.bt.ports`)::

    {"name": "Calculate", "args": {"value": "hp * 2"}, "output": ["double_hp"]}
    {"name": "Index", "args": {"index": 0}, "input": ["targets", ""], "output": ["first"]}

Three rules of behavior3-ts run through them:

* **oneof**: some args can be replaced by an input (Index's ``index`` by its second input).
  When the file binds that input, the variable wins over the arg (:func:`oneof`).
* **Outputs are rewritten when a node finishes**: behavior3-ts sets every bound output after a
  node completes, and setting nothing deletes the variable. So an Index that finds nothing
  *clears* its output, and a FAILURE never leaves a stale value behind.
* **JSON args are fresh each tick**: a Let of ``[]`` writes a new empty list every time, never
  one that an earlier tick has since filled.

Bad input that behavior3-ts answers with its ``error`` status (Push onto something that is not
an array) raises here with a message naming the port and the value: the node returns ERROR and
the message is logged once with the node's id. Expressions are parsed when the tree is loaded,
so a syntax error is a load error that names the node (:mod:`cyborg.bt.expressions`).
"""

from __future__ import annotations

import copy
import logging
import math
import random
import weakref
from collections.abc import Mapping, MutableMapping, Sequence
from typing import Any

from typing_extensions import override

from cyborg.bt.expressions import Expression
from cyborg.bt.js_values import describe, is_number, js_text, read_member, strict_equal, truthy
from cyborg.bt.limits import MAX_VALUE_SIZE
from cyborg.bt.node import Action, Condition, Node
from cyborg.bt.status import FAILURE, SUCCESS, NodeError, Status

log = logging.getLogger("cyborg.bt")

_WARNED: weakref.WeakKeyDictionary[Node, set[str]] = weakref.WeakKeyDictionary()
"""The ports each node has warned about (once each)."""

NO_DEFAULT: Any = object()
"""Marks a :func:`oneof` without a default: an unset bound input is then an error."""


def oneof(node: Node, port: str, arg: Any, default: Any = NO_DEFAULT) -> Any:
    """The value of an arg that input ``port`` may replace, by behavior3-ts's rule.

    When the file binds ``port`` to a variable, that variable's value is used; if it is unset,
    ``default`` stands in (with a warning, logged once), or, without a default, NodeError
    says which input is missing. When ``port`` is unbound, ``arg`` is used, and ``default``
    when ``arg`` is None.
    """
    key = node.ports.get(port)
    value = arg if key is None else node.blackboard.get(key)
    if value is None and key is not None:
        message = f"input {port!r} reads the variable {key!r}, which is not set"
        if default is NO_DEFAULT:
            raise NodeError(message)
        warned = _WARNED.setdefault(node, set())
        if port not in warned:
            warned.add(port)
            log.warning("node %s (%s): %s; using %r", node.uid, node.label, message, default)
    if value is None:
        return None if default is NO_DEFAULT else default
    return value


def fresh(value: Any) -> Any:
    """A JSON arg as behavior3-ts hands it to a node: a new copy of a list or dict each tick."""
    return copy.deepcopy(value) if isinstance(value, list | dict) else value


def array_input(node: Node, port: str, *, to_change: bool = False) -> Sequence[Any]:
    """The array in input ``port``: a list, or also a tuple unless ``to_change``.

    Raises NodeError naming the port when it holds something else.
    """
    value = node.read(port)
    if not isinstance(value, list if to_change else list | tuple):
        raise NodeError(f"input {port!r} ({node.ports.get(port)!r}) must hold an array (a "
                        f"list), not {describe(value)}")
    return value


class Check(Condition):
    """SUCCESS when the expression ``value`` is truthy, else FAILURE.

    ``value`` reads blackboard variables by name: ``hp > 50 && target != null``.
    """

    def __init__(self, value: str) -> None:
        self.expression = Expression(value)

    @override
    def tick(self) -> Status:
        return SUCCESS if truthy(self.expression.evaluate(self.blackboard.globals)) \
            else FAILURE


class Calculate(Action):
    """Evaluates the expression ``value`` into the ``result`` output; SUCCESS."""

    outputs = ("result",)

    def __init__(self, value: str) -> None:
        self.expression = Expression(value)

    @override
    def tick(self) -> Status:
        self.write("result", self.expression.evaluate(self.blackboard.globals))
        return SUCCESS


class Let(Action):
    """Copies a value into the ``variable`` output; SUCCESS.

    The value is the ``existing`` input's variable when the file binds it, else the JSON arg
    ``value``; none (or null) deletes the output variable.
    """

    inputs = ("existing?",)
    outputs = ("variable",)

    def __init__(self, value: Any = None) -> None:
        self.value = value

    @override
    def tick(self) -> Status:
        self.write("variable", oneof(self, "existing", fresh(self.value), None))
        return SUCCESS


class Now(Action):
    """Writes the tree clock's time, in seconds, to the ``time`` output; SUCCESS."""

    outputs = ("time",)

    @override
    def tick(self) -> Status:
        self.write("time", self.now)
        return SUCCESS


class Clear(Action):
    """Deletes the ``variable`` output's variable; SUCCESS (behavior3lua, the editor's sample)."""

    outputs = ("variable",)

    @override
    def tick(self) -> Status:
        self.write("variable", None)
        return SUCCESS


class Includes(Condition):
    """SUCCESS when the ``array`` input holds ``element``, compared as JavaScript's ``===``.

    FAILURE when it does not or ``element`` is unset; an ``array`` that is not one raises.
    """

    inputs = ("array", "element")

    @override
    def tick(self) -> Status:
        array, element = array_input(self, "array"), self.read("element")
        if element is None:
            return FAILURE
        return SUCCESS if any(strict_equal(item, element) for item in array) else FAILURE


class Push(Action):
    """Appends ``element`` to the ``array`` input's list, in place; SUCCESS."""

    inputs = ("array", "element")

    @override
    def tick(self) -> Status:
        array = array_input(self, "array", to_change=True)
        assert isinstance(array, list)
        if len(array) >= MAX_VALUE_SIZE:
            raise NodeError(f"input 'array' holds {len(array):,} items, the most a blackboard "
                            "value may hold")
        array.append(self.read("element"))
        return SUCCESS


class Concat(Action):
    """Writes a new list, ``first`` followed by ``second``, to the ``result`` output; SUCCESS."""

    inputs = ("first", "second")
    outputs = ("result",)

    @override
    def tick(self) -> Status:
        self.write("result", [*array_input(self, "first"), *array_input(self, "second")])
        return SUCCESS


class Index(Action):
    """Writes ``array[index]`` (0-based) to the ``value`` output; SUCCESS.

    FAILURE (and the output deleted) when there is no such element; an index that is not a
    whole number raises. ``index`` is the arg, or the ``index`` input when bound (oneof).
    """

    inputs = ("array", "index?")
    outputs = ("value",)

    def __init__(self, index: int | None = None) -> None:
        self.at = index  # not self.index: every node's index is its place in the tree

    @override
    def tick(self) -> Status:
        array = array_input(self, "array")
        index = oneof(self, "index", self.at)
        if not (is_number(index) and math.isfinite(index) and index == int(index)):
            raise NodeError(f"the index must be a whole number, not {describe(index)} (set the "
                             "index arg or bind the index input)")
        value = read_member(array, index)
        self.write("value", value)
        return FAILURE if value is None else SUCCESS


def _field(node: Node, arg: str | None) -> str | float:
    field = oneof(node, "field", arg)
    if isinstance(field, str | int | float) and not isinstance(field, bool):
        return field
    raise NodeError(f"the field must be text or a number, not {describe(field)} (set the "
                     "field arg or bind the field input)")


def _object(node: Node, *, to_change: bool = False) -> Any:
    target = node.read("object")
    kinds = (MutableMapping, list) if to_change else (Mapping, list, tuple)
    if not isinstance(target, kinds):
        raise NodeError(f"input 'object' ({node.ports.get('object')!r}) must hold an object "
                        f"(a dict) or an array, not {describe(target)}")
    return target


class GetField(Action):
    """Writes ``object[field]`` to the ``value`` output; SUCCESS.

    FAILURE (and the output deleted) when the field is unset. ``field`` is the arg or the bound
    input (oneof).
    """

    inputs = ("object", "field?")
    outputs = ("value",)

    def __init__(self, field: str | None = None) -> None:
        self.field = field

    @override
    def tick(self) -> Status:
        value = read_member(_object(self), _field(self, self.field))
        self.write("value", value)
        return FAILURE if value is None else SUCCESS


class SetField(Action):
    """Sets ``object[field] = value`` in place; a null value deletes the field. SUCCESS.

    ``field`` and ``value`` are args, each replaced by its input when bound (oneof). On an
    array, ``field`` is an index (one past the end appends).
    """

    inputs = ("object", "field?", "value?")

    def __init__(self, field: str | None = None, value: Any = None) -> None:
        self.field = field
        self.value = value

    @override
    def tick(self) -> Status:
        target = _object(self, to_change=True)
        field = _field(self, self.field)
        value = oneof(self, "value", fresh(self.value), None)
        if isinstance(target, MutableMapping):
            key = field if isinstance(field, str) or field in target else js_text(field)
            if value is None:
                target.pop(key, None)
            else:
                target[key] = value
            return SUCCESS
        if isinstance(field, str):
            index = int(field) if field.isdigit() else -1
        else:
            index = int(field) if math.isfinite(field) and field == int(field) else -1
        if not 0 <= index <= len(target):
            raise NodeError(f"field {field!r} is not an index of the {len(target)}-element "
                             "array in input 'object'")
        if index == len(target):
            target.append(value)
        else:
            target[index] = value
        return SUCCESS


class RandomIndex(Action):
    """Writes a random element of the ``array`` input to ``value``, its index to ``index``.

    SUCCESS; an empty array (or a null element drawn) gives FAILURE, the outputs deleted.
    """

    inputs = ("array",)
    outputs = ("value", "index?")

    @override
    def tick(self) -> Status:
        array = array_input(self, "array")
        drawn = random.randrange(len(array)) if array else None
        value = None if drawn is None else array[drawn]
        self.write("value", value)
        self.write("index", None if value is None else drawn)
        return FAILURE if value is None else SUCCESS
