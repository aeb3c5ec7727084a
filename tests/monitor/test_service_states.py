"""The monitor's side of the services on composites: a runner's ``services`` message read for
the page against the structure (unknown composites dropped, texts cut, times clamped), and sent
to the pages watching the tree when it changed, at most four a second, and to a page that
starts watching; hostile messages on the topic never break it."""

from __future__ import annotations

import json
import logging
import random
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cyborg.bus import BusConfig, Context, Node
from cyborg.bus.msgs.builtin_interfaces.msg import Time
from cyborg.bus.msgs.cyborg_msgs.msg import ServiceState, ServiceStates
from cyborg.bus.msgs.diagnostic_msgs.msg import KeyValue
from cyborg.interfaces import tree_runner
from cyborg.monitor import Monitor
from cyborg.monitor.service_link import SERVICES_INTERVAL
from cyborg.monitor.service_wire import (
    ERROR_LIMIT,
    MAX_SERVICES,
    MAX_WROTE,
    NAME_LIMIT,
    VALUE_LIMIT,
    page_services,
)
from cyborg.monitor.tree_state import TreeState
from cyborg.runner.tree_runner import TreeRunnerNode
from tests.monitor.hostile_messages import hostile_service_states
from tests.monitor.monitor_protocol import SMALL_TREE, local_client, next_json, watch
from tests.running_system import wait_until, write_tree
from tests.service_trees import registry, sequence_of, sequence_with
from tests.strict_json import strict_loads


def states(*entries: ServiceState, stamp: float = 12.5) -> ServiceStates:
    return ServiceStates(stamp=Time(sec=int(stamp), nanosec=int(stamp % 1 * 1e9)),
                         tree_id="main", services=list(entries))


def entry(composite: str = "seq", service: str = "Counter", *, runs: int = 3,
          last: Time | None = None, wrote: dict[str, str] | None = None,
          error: str = "", active: bool = True) -> ServiceState:
    return ServiceState(composite=composite, service=service, active=active, runs=runs,
                        last_run=last or Time(sec=12, nanosec=250_000_000),
                        wrote=[KeyValue(key=k, value=v) for k, v in (wrote or {}).items()],
                        error=error)


# ---------------------------------------------------------------------------------- the wire
def test_a_state_reaches_the_page_as_the_runner_said_it() -> None:
    tree = TreeState(SMALL_TREE)
    message = page_services("/cyborg/bt", states(
        entry(wrote={"count": "3", "battery_low": "False"}),
        entry("root", "BatteryWatch", runs=0, active=False, error="RuntimeError: unplugged")),
        tree)
    assert message == {
        "t": "services", "ns": "/cyborg/bt", "v": tree.version, "tree": "main", "time": 12.5,
        "s": [{"id": "seq", "name": "Counter", "active": True, "runs": 3, "last": 12.25,
               "wrote": [["count", "3"], ["battery_low", "False"]], "error": ""},
              {"id": "root", "name": "BatteryWatch", "active": False, "runs": 0, "last": None,
               "wrote": [], "error": "RuntimeError: unplugged"}],
        "dropped": 0}


def test_unknown_composites_are_dropped_and_counted() -> None:
    message = page_services("/cyborg/bt", states(entry("seq"), entry("gone"), entry("")),
                            TreeState(SMALL_TREE))
    assert [service["id"] for service in message["s"]] == ["seq"]
    assert message["dropped"] == 2


def test_long_texts_are_cut_and_an_overfull_nanosecond_count_clamped() -> None:
    message = page_services("/cyborg/bt", states(entry(
        service="S" * 500, wrote={"k" * 500: "v" * 500}, error="E" * 5000,
        last=Time(sec=3, nanosec=4_000_000_000))), TreeState(SMALL_TREE))
    [service] = message["s"]
    assert len(service["name"]) == NAME_LIMIT and service["name"].endswith("…")
    [[key, value]] = service["wrote"]
    assert (len(key), len(value)) == (NAME_LIMIT, VALUE_LIMIT)
    assert len(service["error"]) == ERROR_LIMIT
    assert 3.0 <= service["last"] < 4.0, "the nanoseconds stay within their second"


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.randoms(use_true_random=False))
def test_hostile_messages_become_pages_within_the_limits(rng: random.Random) -> None:
    tree = TreeState(SMALL_TREE)
    incoming = hostile_service_states(rng, list(tree.ids))
    message = page_services("/cyborg/bt", incoming, tree)
    text = json.dumps(message, allow_nan=False)
    assert strict_loads(text) == message
    assert len(message["s"]) + message["dropped"] == len(incoming.services)
    assert len(message["s"]) <= MAX_SERVICES and len(message["tree"]) <= NAME_LIMIT
    for service in message["s"]:
        assert service["id"] in tree.index_of
        assert len(service["name"]) <= NAME_LIMIT and len(service["error"]) <= ERROR_LIMIT
        assert len(service["wrote"]) <= MAX_WROTE
        assert all(len(key) <= NAME_LIMIT and len(value) <= VALUE_LIMIT
                   for key, value in service["wrote"])
        assert (service["last"] is None) == (service["runs"] == 0)


# ---------------------------------------------------------------------------------- on the bus
@pytest.fixture
def served(tmp_path: Path) -> Iterator[tuple[TreeRunnerNode, Monitor, Context]]:
    """A runner whose Sequence carries a 0.02 s Counter, and a monitor following it."""
    tree = write_tree(tmp_path, sequence_with("Counter(interval=0.02)"))
    with Context(BusConfig.isolated()) as context:
        runner = TreeRunnerNode(Node("tree_runner", "/cyborg/bt", context=context), tree,
                                services=registry(), rate_hz=20.0)
        monitor = Monitor(Node("monitor", "/cyborg", context=context),
                          namespaces=["/cyborg/bt"])
        runner.start()
        try:
            yield runner, monitor, context
        finally:
            monitor.stop()
            runner.destroy()


def _next_services(socket: Any) -> dict[str, Any]:
    for _ in range(400):
        message = next_json(socket)
        if message["t"] == "services":
            return message
    raise AssertionError("no services message in 400 messages")


def test_a_watching_page_gets_the_services_and_their_runs_as_they_go(
        served: tuple[TreeRunnerNode, Monitor, Context]) -> None:
    runner, monitor, _context = served
    wait_until(lambda: (source := monitor.hub.sources["/cyborg/bt"]).state is not None
               and source.service_states is not None, 15, "the structure and the services")
    sequence = sequence_of(runner)
    with local_client(monitor.app) as client, client.websocket_connect("/ws") as socket:
        sent = watch(socket, "/cyborg/bt")
        version = next(message["v"] for message in sent if message["t"] == "structure")
        first = _next_services(socket)  # right after the snapshot: what the monitor has
        assert (first["ns"], first["v"], first["tree"]) == ("/cyborg/bt", version,
                                                            runner.tree.tree_id)
        [service] = first["s"]
        assert (service["id"], service["name"], service["active"]) == (sequence, "Counter",
                                                                      True)
        started, sent_before = time.monotonic(), monitor.hub.services.messages
        later = [_next_services(socket) for _ in range(4)]
        counts = [int(dict(message["s"][0]["wrote"])["count"]) for message in later]
        before = int(dict(service["wrote"]).get("count", "0"))
        assert counts == sorted(counts) and counts[-1] > before
        assert all(message["s"][0]["runs"] == count
                   for message, count in zip(later, counts, strict=True))
        assert all(message["s"][0]["last"] <= message["time"] for message in later)
        # 50 runs a second, at most four messages a second (one may have waited already)
        elapsed = time.monotonic() - started
        assert monitor.hub.services.messages - sent_before <= elapsed / SERVICES_INTERVAL + 2


def test_hostile_services_on_the_bus_never_break_the_monitor(
        served: tuple[TreeRunnerNode, Monitor, Context],
        caplog: pytest.LogCaptureFixture) -> None:
    runner, monitor, context = served
    wait_until(lambda: monitor.hub.sources["/cyborg/bt"].state is not None, 15, "the structure")
    state = monitor.hub.sources["/cyborg/bt"].state
    assert state is not None
    runner.set_enabled(False, wait=5.0)  # only the hostile publisher speaks from now on
    source = monitor.hub.sources["/cyborg/bt"]
    wait_until(lambda: source.service_states is not None and source.service_states.services
               and not source.service_states.services[0].active, 15,
               "the runner's last word: its service stopped")
    hostile = Node("intruder", "/elsewhere", context=context)
    publisher = tree_runner.SERVICE_STATES.publisher(hostile, "/cyborg/bt")
    rng = random.Random(23)
    with caplog.at_level(logging.WARNING), local_client(monitor.app) as client, \
            client.websocket_connect("/ws") as socket:
        watch(socket, "/cyborg/bt")
        for _ in range(30):
            publisher.publish(hostile_service_states(rng, list(state.ids)))
        marker = states(entry(sequence_of(runner), "Marker", runs=1))
        publisher.publish(marker)
        while True:  # the marker, the last one published, comes through last
            message = _next_services(socket)
            json.dumps(message, allow_nan=False)
            assert all(service["id"] in state.index_of for service in message["s"])
            if [service["name"] for service in message["s"]] == ["Marker"]:
                break
        socket.send_json({"t": "history", "req": 1})  # and the connection still answers
        while next_json(socket)["t"] != "history":
            pass
    assert not [record for record in caplog.records if record.exc_info], caplog.text
