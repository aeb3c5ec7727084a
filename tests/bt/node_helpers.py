"""Helpers for the tests of the stock nodes (tests/bt/test_stock_nodes.py, test_node_*.py).

Scripted leaves with fixed uids, lifecycle events written compactly as ``"<uid>:<event>"``
tokens (e.g. ``"a:start a:tick a:end:success b:halt"``), statuses as letters (S, F, R, E),
test-only nodes (one that moves the clock, one that returns what is not a Status, ones that
raise in on_start or on_halt, a faulty composite), and building and ticking trees of them on a
manual clock.
"""

from __future__ import annotations

from collections.abc import Sequence

from cyborg.bt import (
    RUNNING,
    SUCCESS,
    Action,
    Composite,
    ManualClock,
    NodeRegistry,
    Status,
    TickSnapshot,
    Tree,
)
from tests.builders import LETTERS, N, registry, tree_from

ROOT = "main"
"""The uid of the Subtree node that holds the tree's root (the tree id used by tree_from)."""


def leaf(uid: str, script: str) -> N:
    """A Scripted leaf with a fixed uid."""
    return N("Scripted", id=uid, script=script)


def parse_events(text: str) -> list[tuple[str, str]]:
    """``"a:start b:end:success"`` -> ``[("start", "a"), ("end:success", "b")]``."""
    parsed: list[tuple[str, str]] = []
    for token in text.split():
        uid, _, event = token.partition(":")
        parsed.append((event, uid))
    return parsed


def letters(statuses: Sequence[Status]) -> str:
    by_status = {status: letter for letter, status in LETTERS.items()}
    return "".join(by_status[status] for status in statuses)


class Advance(Action):
    """Moves the tree's clock forward while it is being ticked (the clock is in the
    blackboard under ``"clock"``), then succeeds."""

    def __init__(self, seconds: float = 1.0) -> None:
        self.seconds = seconds

    def tick(self) -> Status:
        clock: ManualClock = self.blackboard["clock"]
        clock.advance(self.seconds)
        return SUCCESS


class Returns(Action):
    """Returns a value that is not necessarily a Status, chosen by name."""

    VALUES: dict[str, object] = {
        "true": True,
        "false": False,
        "none": None,
        "one": 1,
        "text": "success",
        "status": RUNNING,
    }

    def __init__(self, value: str = "true") -> None:
        self.value = value

    def tick(self) -> Status:
        return self.VALUES[self.value]  # type: ignore[return-value]


class StartBoom(Action):
    """Raises in on_start."""

    def on_start(self) -> None:
        raise ValueError("cannot start")

    def tick(self) -> Status:
        return SUCCESS


class HaltBoom(Action):
    """Keeps running; raises in on_halt."""

    def tick(self) -> Status:
        return RUNNING

    def on_halt(self) -> None:
        raise OSError("cannot cancel")


class Forgetful(Composite):
    """A faulty composite: ticks its first child and succeeds even if the child runs on."""

    def tick(self) -> Status:
        self.children[0].execute()
        return SUCCESS


def custom_registry() -> NodeRegistry:
    reg = registry()
    for cls in (Advance, Returns, StartBoom, HaltBoom, Forgetful):
        reg.add(cls)
    return reg


def build(spec: N) -> Tree:
    tree = tree_from(spec, reg=custom_registry())
    tree.blackboard["clock"] = tree.clock
    return tree


def clock_of(tree: Tree) -> ManualClock:
    clock = tree.clock
    assert isinstance(clock, ManualClock)
    return clock


def run(tree: Tree, advances: Sequence[float]) -> list[TickSnapshot]:
    """Advance the clock by each amount (seconds) and tick once after each."""
    snapshots: list[TickSnapshot] = []
    for seconds in advances:
        clock_of(tree).advance(seconds)
        snapshots.append(tree.tick())
    return snapshots
