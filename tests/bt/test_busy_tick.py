"""A tick that does not end never takes away the stop: it is interrupted when it overruns its
limit, when a halt comes, and when the loop stops; the RUNNING nodes are halted and the node it
was busy in is named (bt.tick_guard, bt.tick_loop)."""

from __future__ import annotations

import threading
import time

import pytest

from cyborg.bt import Action, ManualClock, MonotonicClock, NodeRegistry, Status, TickLoop, Tree
from tests.builders import N, events, registry, tree_from

SPINNING = threading.Event()
"""Set by Spin each time it starts spinning."""


class Spin(Action):
    """Returns RUNNING on its first tick, then loops in Python for ever (a pathological node)."""

    def on_start(self) -> None:
        self.ticked = 0

    def tick(self) -> Status:
        self.ticked += 1
        if self.ticked == 1:
            return Status.RUNNING
        SPINNING.set()
        turns = 0
        while True:
            turns += 1


def spin_registry() -> NodeRegistry:
    nodes = registry()
    nodes.add(Spin)
    return nodes


def spinning_tree() -> Tree:
    """A Parallel of a RUNNING job (records its halt) and a Spin that spins on its 2nd tick."""
    tree = tree_from(N("Parallel", N("Scripted", script="R", tag="job"), N("Spin", id="spin")),
                     clock=ManualClock(), reg=spin_registry())
    tree.clock = MonotonicClock()
    return tree


@pytest.fixture(autouse=True)
def fresh_spin() -> None:
    SPINNING.clear()


def test_a_tick_past_its_limit_is_interrupted_reported_and_the_tree_halted(
        caplog: pytest.LogCaptureFixture) -> None:
    tree = spinning_tree()
    loop = TickLoop(tree, rate_hz=20, clock=tree.clock, tick_limit=0.3)
    reasons: list[str] = []
    told = threading.Event()

    def heard(reason: str) -> None:
        reasons.append(reason)
        told.set()
    loop.add_interrupt_listener(heard)
    loop.start()
    try:
        assert SPINNING.wait(5.0)
        assert told.wait(5.0), "the overrunning tick was interrupted"
        assert "limit of 0.3 s" in reasons[0] and "spin (Spin, Spin)" in reasons[0], reasons
        assert loop.paused, "ticking pauses after an overrun"
        assert ("halt", "job") in events(tree), "the RUNNING job was halted"
        assert tree.running == []
        assert any("interrupted; the tree is halted" in record.getMessage()
                   for record in caplog.records)
    finally:
        loop.stop()


def test_a_halt_interrupts_a_busy_tick_at_once() -> None:
    tree = spinning_tree()
    loop = TickLoop(tree, rate_hz=20, clock=tree.clock, tick_limit=None)
    loop.start()
    try:
        assert SPINNING.wait(5.0)
        started = time.monotonic()
        loop.pause(halt=True)
        took = time.monotonic() - started
        assert took < 2.0, f"the halt waited {took:.2f} s for a tick that never ends"
        assert ("halt", "job") in events(tree)
        assert loop.paused and tree.running == []
    finally:
        loop.stop()


def test_stop_ends_a_loop_busy_in_a_tick() -> None:
    tree = spinning_tree()
    loop = TickLoop(tree, rate_hz=20, clock=tree.clock, tick_limit=None)
    loop.start()
    assert SPINNING.wait(5.0)
    loop.stop(timeout=2.0)
    loop.join(0.1)
    assert loop._thread is not None and not loop._thread.is_alive(), "the loop has ended"
    assert ("halt", "job") in events(tree)


def test_stop_from_another_thread_ends_run_there() -> None:
    """run() in a thread of the caller's (the tree runner's way) stops just as start() does."""
    tree = spinning_tree()
    loop = TickLoop(tree, rate_hz=20, clock=tree.clock, tick_limit=None)
    thread = threading.Thread(target=loop.run, daemon=True)
    thread.start()
    assert SPINNING.wait(5.0)
    loop.stop(timeout=2.0)
    thread.join(0.1)
    assert not thread.is_alive()


def test_a_loop_within_its_limit_is_left_alone() -> None:
    tree = tree_from(N("Wait", milliseconds=300), clock=ManualClock())
    loop = TickLoop(tree, rate_hz=10, tick_limit=0.5)
    told: list[str] = []
    loop.add_interrupt_listener(told.append)
    loop.run(until_done=True)
    assert tree.last is not None and tree.last.status is Status.SUCCESS and told == []


def test_a_tick_limit_must_be_positive() -> None:
    with pytest.raises(ValueError, match="tick limit"):
        TickLoop(tree_from(N("Runner")), tick_limit=0)
