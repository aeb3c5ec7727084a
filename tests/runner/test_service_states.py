"""The tree runner publishes the states of the services on its composites on ``<ns>/services``:
when they change, at most a few times a second, latched; nothing for a tree without services,
one empty message when a reload leaves none. On an isolated bus, no robot."""

from __future__ import annotations

import itertools
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import pytest

from cyborg.bus import BusConfig, Context, Node
from cyborg.bus.msgs.cyborg_msgs.msg import ServiceStates
from cyborg.bus.msgs.std_msgs.msg import String
from cyborg.interfaces import modes, tree_runner
from cyborg.runner.tree_runner import TreeRunnerNode
from tests.builders import N, project_json, tree_json
from tests.running_system import wait_until, write_tree
from tests.service_trees import registry, sequence_of, sequence_with

NAMESPACE = "/cyborg/bt"


@pytest.fixture
def bus() -> Iterator[Context]:
    context = Context(BusConfig.isolated())
    yield context
    context.close()


class Listener:
    """Collects what the runner publishes on ``services``."""

    def __init__(self, bus: Context, name: str = "listener") -> None:
        self.node = Node(name, "/test", context=bus)
        self.messages: list[tuple[float, ServiceStates]] = []
        self._lock = threading.Lock()
        tree_runner.SERVICE_STATES.subscription(self.node, self._on, NAMESPACE)

    def _on(self, message: ServiceStates) -> None:
        with self._lock:
            self.messages.append((time.monotonic(), message))

    def received(self) -> list[ServiceStates]:
        with self._lock:
            return [message for _, message in self.messages]

    def last(self) -> ServiceStates | None:
        received = self.received()
        return received[-1] if received else None


@contextmanager
def runner_on(bus: Context, tree: Path, **options: Any) -> Iterator[TreeRunnerNode]:
    runner = TreeRunnerNode(Node("tree_runner", NAMESPACE, context=bus), tree,
                            services=registry(), **options)
    runner.start()
    try:
        yield runner
    finally:
        runner.destroy()


def seconds(stamp: Any) -> float:
    return float(stamp.sec + stamp.nanosec * 1e-9)


def counted(message: ServiceStates | None) -> int:
    """What Counter last wrote, as the message says it (0 before it wrote)."""
    if message is None or not message.services:
        return 0
    wrote = {pair.key: pair.value for pair in message.services[0].wrote}
    return int(wrote.get("count", "0"))


def test_a_running_service_is_published_with_its_runs_last_run_and_what_it_wrote(
        bus: Context, tmp_path: Path) -> None:
    tree = write_tree(tmp_path, sequence_with("Counter(interval=0.05)"))
    listener = Listener(bus)
    with runner_on(bus, tree) as runner:
        sequence = sequence_of(runner)
        wait_until(lambda: counted(listener.last()) >= 10, timeout=15,
                   what="Counter's count published")
        message = listener.last()
        assert message is not None and message.tree_id == runner.tree.tree_id
        [state] = message.services
        assert (state.composite, state.service, state.active, state.error) == \
            (sequence, "Counter", True, "")
        assert state.runs == counted(message), "each run wrote the count once"
        assert 0 < seconds(state.last_run) <= seconds(message.stamp)
        runs = [message.services[0].runs for message in listener.received() if message.services]
        assert runs == sorted(runs), "the runs only grow"
        # a monitor that comes late gets the last states (latched)
        late = Listener(bus, "late")
        wait_until(lambda: late.received(), timeout=10, what="the latched states")
        assert late.received()[0].services[0].composite == sequence


def test_at_most_a_few_messages_a_second_and_the_last_change_always_goes_out(
        bus: Context, tmp_path: Path) -> None:
    """The service runs 50 times a second; the runner publishes at most 4 a second, and when
    the runs stop (the tree disabled) the final state still comes."""
    tree = write_tree(tmp_path, sequence_with("Counter(interval=0.02)"))
    listener = Listener(bus)
    with runner_on(bus, tree, rate_hz=50.0) as runner:
        wait_until(lambda: counted(listener.last()) >= 40, timeout=15, what="40 runs published")
        runner.set_enabled(False, wait=5.0)
        wait_until(lambda: (last := listener.last()) is not None and last.services
                   and not last.services[0].active, timeout=10,
                   what="the service shown stopped after the disable")
        with listener._lock:
            times = [at for at, _ in listener.messages]
        gaps = [later - earlier for earlier, later in itertools.pairwise(times)]
        interval = 1.0 / tree_runner.SERVICE_STATES_PER_SECOND
        # delivery may bunch two messages up; the publisher never sends them closer
        assert len(times) <= (times[-1] - times[0]) / interval + 2, gaps
        final = listener.last()
        assert final is not None
        assert final.services[0].runs == runner.tree.services.services[0].runs  # type: ignore[union-attr]


def test_services_that_run_between_ticks_are_published_between_ticks(
        bus: Context, tmp_path: Path) -> None:
    """A tree that ticks every 5 s with a 0.05 s service: the states change between ticks."""
    tree = write_tree(tmp_path, sequence_with("Counter(interval=0.05)"))
    listener = Listener(bus)
    with runner_on(bus, tree, rate_hz=0.2) as runner:
        wait_until(lambda: counted(listener.last()) >= 1, timeout=15, what="a first run shown")
        ticks, seen = runner.tree.ticks, counted(listener.last())
        wait_until(lambda: counted(listener.last()) > seen, timeout=4,
                   what="a run between two ticks published")
        assert runner.tree.ticks == ticks, "no tick came meanwhile (the tree ticks every 5 s)"


def test_an_error_is_published_and_the_service_shown_stopped(bus: Context,
                                                            tmp_path: Path) -> None:
    tree = write_tree(tmp_path, sequence_with("Counter; Broken"))
    listener = Listener(bus)
    with runner_on(bus, tree):
        wait_until(lambda: any(state.error for message in listener.received()
                               for state in message.services), timeout=15,
                   what="Broken's error published")
        message = listener.last()
        assert message is not None
        broken = next(state for state in message.services if state.service == "Broken")
        assert broken.error == "RuntimeError: the sensor is unplugged"
        assert not broken.active
        counter = next(state for state in message.services if state.service == "Counter")
        assert counter.active and not counter.error, "the other service goes on"


def test_a_tree_without_services_publishes_nothing_and_a_reload_to_one_says_none_are_left(
        bus: Context, tmp_path: Path) -> None:
    plain = write_tree(tmp_path, {"name": "Sequence", "children": [{"name": "Runner"}]},
                       "plain.b3.json")
    served = write_tree(tmp_path, sequence_with("Counter"), "served.b3.json")
    listener = Listener(bus)
    with runner_on(bus, plain) as runner:
        wait_until(lambda: runner.tree.ticks > 20, timeout=15, what="20 ticks")
        assert listener.received() == [], "a tree without services publishes nothing"
        runner.reload(served)
        wait_until(lambda: counted(listener.last()) >= 1, timeout=15,
                   what="the reloaded tree's services")
        runner.reload(plain)
        wait_until(lambda: (last := listener.last()) is not None and not last.services,
                   timeout=15, what="an empty message after the reload")
        count = len(listener.received())
        ticks = runner.tree.ticks
        wait_until(lambda: runner.tree.ticks > ticks + 20, timeout=15, what="20 more ticks")
        assert len(listener.received()) == count, "the empty message is said once"


def test_a_disabled_runner_reloading_a_tree_with_services_shows_them_idle(
        bus: Context, tmp_path: Path) -> None:
    plain = write_tree(tmp_path, {"name": "Sequence", "children": [{"name": "Runner"}]},
                       "plain.b3.json")
    served = write_tree(tmp_path, sequence_with("Counter"), "served.b3.json")
    listener = Listener(bus)
    with runner_on(bus, plain, enabled=False) as runner:
        runner.reload(served)
        wait_until(lambda: listener.last() is not None, timeout=10,
                   what="the new tree's services, with no tick to tell of them")
        message = listener.last()
        assert message is not None
        [state] = message.services
        assert (state.service, state.active, state.runs, list(state.wrote)) == \
            ("Counter", False, 0, [])
        assert state.composite == sequence_of(runner)


MODES = """\
project = "mission.b3.json"
initial = "normal"
[modes.normal]
tree = "patrol"
[modes.demo]
tree = "demo"

[[transitions]]
from = "normal"
to = "demo"
event = "show"
"""


def test_a_mode_file_publishes_the_current_modes_services_and_none_in_a_mode_without(
        bus: Context, tmp_path: Path) -> None:
    patrol = tree_json(N("Sequence", N("Runner"), services="Counter(interval=0.05)"),
                       tree_id="patrol", title="patrol")
    demo = tree_json(N("Sequence", N("Runner")), tree_id="demo", title="demo")
    (tmp_path / "mission.b3.json").write_text(project_json([patrol, demo]))
    modes_file = tmp_path / "mission.modes.toml"
    modes_file.write_text(MODES)
    listener = Listener(bus)
    events = modes.EVENTS.publisher(listener.node, NAMESPACE)
    with runner_on(bus, modes_file) as runner:
        wait_until(lambda: counted(listener.last()) >= 3, timeout=15,
                   what="the normal mode's Counter published")
        last = listener.last()
        assert last is not None and last.tree_id == "patrol"
        assert last.services[0].composite == sequence_of(runner)

        def in_demo() -> bool:  # the event again until the runner's subscription has it
            if runner.tree.title != "demo":
                events.publish(String(data="show"))
            return runner.tree.title == "demo"
        wait_until(in_demo, timeout=15, what="the demo mode")
        wait_until(lambda: (message := listener.last()) is not None and not message.services,
                   timeout=15, what="an empty message in the mode without services")
        assert listener.last().tree_id == "demo"  # type: ignore[union-attr]
