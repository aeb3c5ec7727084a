"""Helpers for the tests of behavior3 v1's stock nodes (tests/bt/test_v1_*.py).

Compact builders of v1 nodes (``n``, and ``s`` for a Scripted leaf, ``seq``, ``check``, ...),
a loader that registers behavior3-ts's test-only nodes (IsStatus, Attack) and ticks on a manual
clock, a runner that spells the tree's status per tick as letters (S, F, R, E), and a log
handler that collects the messages Log nodes print. The fixtures built on them (fresh node ids
for every test, ``lines``) are in tests/bt/conftest.py.
"""

from __future__ import annotations

import itertools
import json
import logging
from pathlib import Path
from typing import Any

import pytest

from cyborg.bt import (
    Action,
    Blackboard,
    Condition,
    ManualClock,
    NodeRegistry,
    Status,
    Tree,
    TreeLoadError,
    loads_tree,
)
from tests.builders import registry

SAMPLES = Path(__file__).resolve().parent / "data" / "behavior3_v1"
TS_EXAMPLE = SAMPLES / "behavior3-ts-example"
LETTER = {Status.SUCCESS: "S", Status.FAILURE: "F", Status.RUNNING: "R", Status.ERROR: "E"}

_ids = itertools.count(1)


def fresh_ids() -> None:
    """Number the nodes :func:`n` builds from 1 again (done before every test)."""
    global _ids
    _ids = itertools.count(1)


def n(name: str, *children: dict[str, Any], args: dict[str, Any] | None = None,
      i: list[str] | None = None, o: list[str] | None = None) -> dict[str, Any]:
    """A v1 node; ``i``/``o`` are its input/output bindings."""
    node: dict[str, Any] = {"id": str(next(_ids)), "name": name}
    if args:
        node["args"] = args
    if i is not None:
        node["input"] = i
    if o is not None:
        node["output"] = o
    if children:
        node["children"] = list(children)
    return node


def s(script: str, tag: str) -> dict[str, Any]:
    """A Scripted leaf: one status letter per tick (S, F, R, E; X raises)."""
    return n("Scripted", args={"script": script, "tag": tag})


def log(message: str) -> dict[str, Any]:
    return n("Log", args={"message": message, "level": "info"})


def let(value: Any, out: str, i: list[str] | None = None) -> dict[str, Any]:
    return n("Let", args={} if value is None else {"value": value},
             i=[""] if i is None else i, o=[out])


def seq(*children: dict[str, Any]) -> dict[str, Any]:
    return n("Sequence", *children)


def wait(seconds: float) -> dict[str, Any]:
    return n("Wait", args={"time": seconds})


def ok(child: dict[str, Any]) -> dict[str, Any]:
    return n("AlwaysSuccess", child)


def check(expression: str) -> dict[str, Any]:
    return n("Check", args={"value": expression})


def calc(expression: str, out: str) -> dict[str, Any]:
    return n("Calculate", args={"value": expression}, o=[out])


class IsStatus(Condition):
    """behavior3-ts's test-only node (example/node-config.b3-setting): tick the one child and
    succeed when it returned ``status``; a RUNNING child is halted (its stack is dropped)."""

    def __init__(self, status: str) -> None:
        self.wanted = Status.parse(status)

    def check(self) -> list[str]:
        return [] if len(self.children) == 1 else ["IsStatus takes exactly one child"]

    def tick(self) -> Status:
        child = self.children[0]
        status = child.execute()
        if status is Status.RUNNING:
            child.halt()
        return Status.SUCCESS if status is self.wanted else Status.FAILURE


class Attack(Action):
    """Stand-in for behavior3-ts's game node in test-array.json: it succeeds."""

    inputs = ("target",)

    def tick(self) -> Status:
        return Status.SUCCESS


def _registry() -> NodeRegistry:
    reg = registry()
    reg.add(IsStatus)
    reg.add(Attack)
    return reg


def load(root: dict[str, Any], **variables: Any) -> tuple[Tree, ManualClock]:
    clock = ManualClock()
    tree = loads_tree(json.dumps({"name": "t", "root": root}), registry=_registry(),
                      clock=clock, blackboard=Blackboard({"events": [], **variables}))
    return tree, clock


def run(tree: Tree, clock: ManualClock, ticks: int, step: float = 1.0) -> str:
    """Tick ``ticks`` times, advancing ``step`` seconds before each; the status letters."""
    letters = ""
    for _ in range(ticks):
        clock.advance(step)
        letters += LETTER[tree.tick().status]
    return letters


def load_error(root: dict[str, Any]) -> str:
    with pytest.raises(TreeLoadError) as caught:
        load(root)
    return str(caught.value)


class LogLines(logging.Handler):
    """The messages Log nodes write, tick by tick."""

    def __init__(self) -> None:
        super().__init__(logging.DEBUG)
        self.lines: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:
        args = record.args  # Log logs ("%s", message) or ("%s %r", message, value)
        self.lines.append(str(args[0]) if isinstance(args, tuple) and args
                          else record.getMessage())

    def take(self) -> list[str]:
        lines, self.lines = self.lines, []
        return lines
