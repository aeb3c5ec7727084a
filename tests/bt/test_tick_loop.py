"""The runner: fixed rate on the tree's clock, pause/resume/step/stop, snapshots to listeners."""

from __future__ import annotations

import threading
import time

import pytest

from cyborg.bt import ManualClock, MonotonicClock, Status, TickLoop, TickSnapshot
from tests.builders import N, events, tree_from


def test_ticks_at_the_rate_on_a_manual_clock() -> None:
    clock = ManualClock()
    tree = tree_from(N("Wait", milliseconds=1000), clock=clock)
    seen: list[TickSnapshot] = []
    runner = TickLoop(tree, rate_hz=10)
    runner.add_listener(seen.append)
    runner.run(until_done=True)
    # Ticks at t = 0.0, 0.1, ..., 1.0: the Wait succeeds in the 11th tick.
    assert [s.time for s in seen] == pytest.approx([i / 10 for i in range(11)])
    assert seen[-1].status is Status.SUCCESS
    assert [s.tick for s in seen] == list(range(1, 12))


def test_default_rate_is_10_hz_and_max_ticks() -> None:
    clock = ManualClock()
    runner = TickLoop(tree_from(N("Runner"), clock=clock))
    assert runner.rate_hz == 10
    runner.run(max_ticks=5)
    assert clock.now() == pytest.approx(0.4)
    assert runner.tree.ticks == 5


def test_stop_halts_running_nodes() -> None:
    tree = tree_from(N("Sequence", N("Scripted", script="R", tag="job")))
    runner = TickLoop(tree)
    runner.run(max_ticks=3)
    assert events(tree)[-1] == ("halt", "job")
    assert tree.running == []


def test_pause_resume_step_and_stop_in_background() -> None:
    tree = tree_from(N("Scripted", script="R", tag="job"), clock=None)
    tree.clock = MonotonicClock()
    runner = TickLoop(tree, rate_hz=200, clock=tree.clock)
    ticked = threading.Event()
    runner.add_listener(lambda snapshot: ticked.set())
    runner.start()
    assert ticked.wait(2.0)
    runner.pause()
    time.sleep(0.05)
    paused_at = tree.ticks
    time.sleep(0.1)
    assert tree.ticks == paused_at, "a paused runner does not tick"
    assert runner.paused
    assert events(tree)[-1] == ("tick", "job"), "pausing does not halt by default"
    snapshot = runner.step()
    assert snapshot.tick == paused_at + 1
    runner.resume()
    deadline = time.monotonic() + 2.0
    while tree.ticks < paused_at + 5 and time.monotonic() < deadline:
        time.sleep(0.01)
    assert tree.ticks >= paused_at + 5
    runner.stop()
    assert runner.stopped
    assert events(tree)[-1] == ("halt", "job")


def test_pause_with_halt_stops_running_actions() -> None:
    tree = tree_from(N("Scripted", script="R", tag="job"))
    runner = TickLoop(tree)
    runner.step()
    runner.pause(halt=True)
    assert events(tree)[-1] == ("halt", "job")
    runner.step()
    assert events(tree)[-2:] == [("start", "job"), ("tick", "job")], "restarts cleanly"


def test_a_raising_listener_does_not_stop_the_tree(caplog: pytest.LogCaptureFixture) -> None:
    tree = tree_from(N("Runner"))
    runner = TickLoop(tree)

    def broken(snapshot: TickSnapshot) -> None:
        raise RuntimeError("listener bug")

    runner.add_listener(broken)
    runner.run(max_ticks=3)
    assert tree.ticks == 3
    assert "listener" in caplog.text


def test_remove_listener() -> None:
    runner = TickLoop(tree_from(N("Runner")))
    seen: list[int] = []
    remove = runner.add_listener(lambda s: seen.append(s.tick))
    runner.step()
    remove()
    runner.step()
    assert seen == [1]


@pytest.mark.parametrize("rate", [0, -1])
def test_bad_rate(rate: float) -> None:
    with pytest.raises(ValueError, match="tick rate must be more than 0"):
        TickLoop(tree_from(N("Runner")), rate_hz=rate)


def test_overrun_does_not_burst() -> None:
    """A tick slower than its slot is followed at once, without catch-up ticks."""
    clock = ManualClock()

    class SlowClock(ManualClock):
        pass

    tree = tree_from(N("Runner"), clock=clock)
    runner = TickLoop(tree, rate_hz=10)
    times: list[float] = []

    def slow(snapshot: TickSnapshot) -> None:
        times.append(snapshot.time)
        if snapshot.tick == 2:
            clock.advance(0.55)  # this tick took 0.55 s of clock time

    runner.add_listener(slow)
    runner.run(max_ticks=5)
    assert times == pytest.approx([0.0, 0.1, 0.65, 0.75, 0.85])


def test_decimal_clock_steps_do_not_cost_an_extra_tick() -> None:
    """0.35 s - 0.1 s is 249.99999999999997 ms in floating point; it counts as 250 ms."""
    clock = ManualClock(0.1)
    tree = tree_from(N("Timeout", N("Runner"), milliseconds=250), clock=clock)
    assert tree.tick().status is Status.RUNNING
    clock.set(0.35)
    assert tree.tick().status is Status.FAILURE


def test_service_listeners_hear_of_runs_between_ticks_and_of_a_halt_that_stops_them() -> None:
    from tests.bt.service_helpers import probe_tree

    tree = probe_tree(N("Sequence", N("Runner"), id="seq", services="Probe(interval=0.02)"))
    tree.clock = MonotonicClock()
    loop = TickLoop(tree, rate_hz=0.2)  # one tick, then service runs only
    heard: list[tuple[int, bool, str]] = []
    remove = loop.add_service_listener(lambda services: heard.append(
        (tree.ticks, services.states()[0].active, threading.current_thread().name)))
    loop.start()
    deadline = time.monotonic() + 30.0
    while len(heard) < 3 and time.monotonic() < deadline:
        time.sleep(0.01)
    assert len(heard) >= 3 and {ticks for ticks, _, _ in heard} == {1}, heard
    assert all(active and thread == "bt:Main" for _, active, thread in heard), heard
    heard.clear()
    loop.pause(halt=True)
    assert heard and heard[-1][1] is False, "the halt stopped the service, and said so"
    remove()
    loop.stop(timeout=30.0)
    count = len(heard)
    loop.step()
    assert len(heard) == count, "a removed listener hears nothing more"
