"""Simulated time under attack and faults: forged /clock messages, jumps, stalls, restarts.

Every test runs on an isolated bus (or two sessions linked on loopback) and every wait is
bounded. A "simulator" here is a publisher on ``/clock`` stepping time in a thread.
"""

from __future__ import annotations

import json
import logging
import threading
import time
from collections.abc import Iterator
from typing import Any

import pytest

from cyborg.bt import TickLoop, TickSnapshot, loads_tree
from cyborg.bus import BusConfig, Context, Node, Qos
from cyborg.bus.clock import CLOCK_TYPE, SimClock
from tests.builders import N, registry, tree_json
from tests.bus.bus_peer import forged, linked_contexts, raw_put, until_subscribed, wait_for


@pytest.fixture
def bus() -> Iterator[Context]:
    context = Context(BusConfig.isolated())
    yield context
    context.close()


def clock_message(types: Any, seconds: float) -> Any:
    sec, nanosec = divmod(round(seconds * 1e9), 1_000_000_000)
    stamp = types.message_class("builtin_interfaces/msg/Time")(sec=sec, nanosec=nanosec)
    return types.message_class(CLOCK_TYPE)(clock=stamp)


class Simulator:
    """Publishes /clock from ``start`` in steps of ``step`` s every 2 ms of wall time."""

    def __init__(self, context: Context, name: str = "sim", start: float = 0.0,
                 step: float = 0.05) -> None:
        self.node = Node(name, context=context)
        self.publisher = self.node.create_publisher("/clock", CLOCK_TYPE)
        self.time, self.step = start, step
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)

    def publish(self, seconds: float) -> None:
        self.publisher.publish(clock_message(self.node.types, seconds))

    def _run(self) -> None:
        while not self._stop.wait(0.002):
            self.publish(self.time)
            self.time += self.step

    def start(self) -> Simulator:
        self._thread.start()
        return self

    def stop(self) -> None:
        """The simulator process ends: no more /clock, and its publisher leaves the graph."""
        self._stop.set()
        if self._thread.is_alive():
            self._thread.join(2)
        self.node.destroy()


class Ticking:
    """A TickLoop on ``clock`` at 50 Hz of simulated time, counting its ticks."""

    def __init__(self, clock: SimClock) -> None:
        reg = registry()
        tree = loads_tree(json.dumps(tree_json(N("Runner"), reg=reg)), registry=reg,
                          clock=clock)
        self.runner = TickLoop(tree, rate_hz=50, clock=clock)
        self.ticks: list[float] = []
        self.runner.add_listener(self._on_tick)
        self.runner.start()

    def _on_tick(self, snapshot: TickSnapshot) -> None:
        self.ticks.append(snapshot.time)

    def ticks_within(self, wall_seconds: float) -> int:
        before = len(self.ticks)
        time.sleep(wall_seconds)
        return len(self.ticks) - before

    def stop(self) -> None:
        self.runner.stop()
        self.runner.join(5)


def sleeper(clock: SimClock, deadline: float) -> threading.Thread:
    thread = threading.Thread(target=clock.sleep_until, args=(deadline, threading.Event()),
                              daemon=True)
    thread.start()
    return thread


def messages(caplog: pytest.LogCaptureFixture, *words: str) -> list[str]:
    return [r.getMessage() for r in caplog.records
            if all(word in r.getMessage() for word in words)]


# ---------------------------------------------------------------------- forged future times
def test_a_forged_far_future_clock_does_not_freeze_the_runner(
        bus: Context, caplog: pytest.LogCaptureFixture) -> None:
    sim = Simulator(bus).start()
    clock = SimClock(Node("runner", context=bus))
    assert clock.wait_for_time(5)
    ticking = Ticking(clock)
    try:
        assert wait_for(lambda: len(ticking.ticks) >= 3)
        forger = Node("forger", context=bus).create_publisher("/clock", CLOCK_TYPE)
        with caplog.at_level(logging.WARNING, "cyborg.bus"):
            forger.publish(clock_message(bus.types, 2_000_000_000))
            assert ticking.ticks_within(0.5) >= 5, "the runner stopped ticking"
        assert clock.now() < 1000 and abs(clock.now() - sim.time) < 5
        assert clock.ignored >= 1
        assert messages(caplog, "/clock", "ignor")  # said, not silent
    finally:
        ticking.stop()
        sim.stop()


def test_forged_clocks_from_the_network_are_ignored(caplog: pytest.LogCaptureFixture) -> None:
    with linked_contexts() as (victim, attacker):
        sim = Simulator(victim).start()
        clock = SimClock(Node("runner", context=victim))
        assert clock.wait_for_time(5)
        until_subscribed(attacker, "/clock")
        payload = bytes(attacker.types.serialize(clock_message(attacker.types, 2e9), CLOCK_TYPE))
        with caplog.at_level(logging.WARNING, "cyborg.bus"):
            raw_put(attacker, "/clock", CLOCK_TYPE, payload, None)  # no attachment
            raw_put(attacker, "/clock", CLOCK_TYPE, payload, forged(1))  # a made-up GID
            assert wait_for(lambda: clock.ignored >= 2)
        time.sleep(0.05)
        assert clock.now() < 1000 and abs(clock.now() - sim.time) < 5
        sim.stop()


# ---------------------------------------------------------------------- jumps of the publisher
def test_a_backward_jump_of_the_clock_publisher_wakes_sleepers(
        bus: Context, caplog: pytest.LogCaptureFixture) -> None:
    sim = Simulator(bus)
    clock = SimClock(Node("runner", context=bus), jump_limit=1.0)
    sim.publish(100.0)
    assert wait_for(lambda: clock.now() == 100.0)
    waiting = sleeper(clock, 200.0)
    with caplog.at_level(logging.INFO, "cyborg.bus"):
        sim.publish(3.0)
        waiting.join(2)
    assert not waiting.is_alive(), "a sleeper slept through a backward jump"
    assert clock.now() == 3.0 and clock.jumps == 1
    assert messages(caplog, "/clock", "back", "100", "3")


def test_a_forward_jump_of_the_clock_publisher_is_followed_and_logged(
        bus: Context, caplog: pytest.LogCaptureFixture) -> None:
    sim = Simulator(bus)
    clock = SimClock(Node("runner", context=bus), jump_limit=1.0)
    sim.publish(1.0)
    assert wait_for(lambda: clock.now() == 1.0)
    with caplog.at_level(logging.WARNING, "cyborg.bus"):
        sim.publish(5000.0)
        assert wait_for(lambda: clock.now() == 5000.0)
        sim.publish(5000.5)  # within the limit: quiet
        assert wait_for(lambda: clock.now() == 5000.5)
    assert clock.jumps == 1
    assert len(messages(caplog, "/clock", "forward")) == 1


def test_a_restarted_simulator_is_followed_at_once(bus: Context,
                                                   caplog: pytest.LogCaptureFixture) -> None:
    first = Simulator(bus, "sim", start=1000.0).start()
    clock = SimClock(Node("runner", context=bus))
    assert clock.wait_for_time(5)
    ticking = Ticking(clock)
    try:
        assert wait_for(lambda: len(ticking.ticks) >= 3)
        first.stop()
        time.sleep(0.1)
        second = Simulator(bus, "sim2", start=0.0).start()  # time starts again from 0
        with caplog.at_level(logging.INFO, "cyborg.bus"):
            assert wait_for(lambda: clock.now() < 100, 2), "the new simulator was ignored"
            assert ticking.ticks_within(0.5) >= 5, "ticking did not resume"
        assert messages(caplog, "/clock", "back")
        second.stop()
    finally:
        ticking.stop()


def test_a_second_publisher_is_ignored_until_the_first_leaves(bus: Context) -> None:
    first, second = Simulator(bus, "sim"), Simulator(bus, "sim2")
    clock = SimClock(Node("runner", context=bus))
    first.publish(10.0)
    assert wait_for(lambda: clock.now() == 10.0)
    second.publish(10.5)  # close in time, still not ours
    first.publish(10.1)
    assert wait_for(lambda: clock.now() == pytest.approx(10.1))
    assert clock.ignored == 1
    first.stop()

    def followed() -> bool:
        second.publish(11.0)  # until the first publisher has left the graph
        return clock.now() == 11.0
    assert wait_for(followed, 2)


# ---------------------------------------------------------------------- stalls
def test_stalled_simulated_time_is_logged_and_so_is_its_end(
        bus: Context, caplog: pytest.LogCaptureFixture) -> None:
    sim = Simulator(bus)
    clock = SimClock(Node("runner", context=bus), stall_timeout=0.2)
    sim.publish(7.0)
    assert wait_for(lambda: clock.now() == 7.0)
    with caplog.at_level(logging.INFO, "cyborg.bus"):
        waiting = sleeper(clock, 8.0)
        assert wait_for(lambda: messages(caplog, "simulated time", "7"), 2), \
            "a stall went unreported"
        assert len(messages(caplog, "simulated time", "not advanced")) == 1  # once per stall
        sim.publish(8.0)
        waiting.join(2)
        assert wait_for(lambda: messages(caplog, "simulated time", "again"), 2)
    assert not waiting.is_alive()


def test_in_process_clock_messages_keep_their_order(bus: Context) -> None:
    """A dispatch the node's thread has taken off its queue but not yet run must not be
    overtaken by a message handed over directly: the clock would step back and wake sleepers."""
    sim = Simulator(bus)
    node = Node("runner", context=bus)
    clock = SimClock(node)
    gate = threading.Event()
    node.callbacks.submit(gate.wait, 5)  # the node is busy
    time.sleep(0.05)
    sim.publish(1.0)  # queued behind the busy callback
    function, args = node.callbacks._queue.get(timeout=1)  # the thread takes it...
    gate.set()
    time.sleep(0.05)  # ...and the node is idle again before it runs
    sim.publish(2.0)
    function(*args)
    assert wait_for(lambda: clock.now() == 2.0)
    time.sleep(0.05)
    assert clock.now() == 2.0 and clock._epoch == 0  # never went back to 1.0


def test_a_clock_created_after_a_latched_clock_message_follows_it_without_error(
        bus: Context, caplog: pytest.LogCaptureFixture) -> None:
    """A /clock message already waiting in the process (latched) arrives while the SimClock
    subscribes; it used to raise AttributeError ('topic') inside the callback."""
    node = Node("sim", context=bus)
    publisher = node.create_publisher("/clock", CLOCK_TYPE, Qos.latched())
    publisher.publish(clock_message(bus.types, 42.0))
    with caplog.at_level(logging.WARNING):
        clock = SimClock(Node("runner", context=bus))
        assert clock.wait_for_time(5) and clock.now() == 42.0
    assert not [record for record in caplog.records if "raised" in record.getMessage()]
