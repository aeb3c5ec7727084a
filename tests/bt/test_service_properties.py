"""Property tests of the services' lifecycle on random trees, in the style of the halting rules.

Random trees of composites, decorators and `Scripted` leaves (tests/bt/test_halting_properties.py)
get `Probe` services on random composites, with random intervals, deviations, activation
options and failures. The clock moves a random amount between ticks, the services due in
between are run as the TickLoop runs them, and the tree is sometimes halted as a whole. After
every step:

(a) per service, the log is a sequence of activations: ``on_activate``, then ``run`` any number
    of times, then exactly one ``on_deactivate``; nothing happens outside an activation;
(b) a composite that became RUNNING in a tick activated each of its services once in that
    tick, and one whose activation ended (it completed, or it was halted) deactivated each
    still-active service once; no other composite's services started or stopped;
(c) the active services are exactly those of RUNNING composites, less those that raised in
    this activation;
(d) a service runs only while active; the first run of an activation comes at most one
    interval plus the deviation after it, and so does each run after another; with the timer
    restarted on activation, runs are at least one interval less the deviation apart;
(e) after tree.halt() no service is active and no activation is left open.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cyborg.bt import RUNNING, Tree
from cyborg.bt.service_runner import ScheduledService
from tests.bt.service_helpers import Event, Probe, advance, probe_registry, service_log
from tests.bt.test_halting_properties import COMPOSITES, HALT, node_specs, operations, renumber
from tests.builders import N, tree_from

EPSILON = 1e-6


@st.composite
def declarations(draw: st.DrawFn) -> str:
    """One or two probes with random common options and, sometimes, a failure."""
    calls = []
    for name in draw(st.sampled_from([["Probe"], ["OtherProbe"], ["Probe", "OtherProbe"]])):
        interval = draw(st.sampled_from([0.05, 0.1, 0.25, 0.5, 1.0, 2.5]))
        options = [f"interval={interval}"]
        if draw(st.booleans()):
            options.append(f"deviation={draw(st.sampled_from([0.0, 0.4, 0.9])) * interval}")
        if draw(st.booleans()):
            options.append("restart_on_activation=false")
        if draw(st.booleans()):
            options.append("run_on_activation=true")
        if draw(st.integers(0, 5)) == 0:
            fail = draw(st.sampled_from(["on_activate", "run", "on_deactivate"]))
            options.append(f"fail={fail}, fail_after={draw(st.integers(0, 3))}")
        calls.append(f"{name}({', '.join(options)})")
    return "; ".join(calls)


@st.composite
def serviced_trees(draw: st.DrawFn) -> N:
    spec = renumber(draw(node_specs()))
    pending = [spec]
    while pending:
        node = pending.pop()
        pending.extend(node.children)
        if node.name in COMPOSITES and draw(st.integers(0, 2)) > 0:
            node.props["services"] = draw(declarations())
    return spec


@dataclass
class ServiceChecker:
    """Follows the services of a tree step by step and checks every rule after each step."""

    tree: Tree
    open: dict[tuple[str, str], float] = field(default_factory=dict)
    """(composite, service) -> start of its open activation."""
    last_run: dict[tuple[str, str], float] = field(default_factory=dict)
    failed: set[tuple[str, str]] = field(default_factory=set)
    """Services that raised and were stopped in their composite's current activation."""
    active: set[str] = field(default_factory=set)
    """Composites with services that were RUNNING after the last step."""
    calls: Counter[tuple[str, str]] = field(default_factory=Counter)
    """Calls of each probe's failing method so far (it raises after `fail_after` of them)."""
    raised: set[tuple[str, str]] = field(default_factory=set)
    """Probes that raised and have not been deactivated yet: their next event must be that."""

    def __post_init__(self) -> None:
        assert self.tree.services is not None
        self.scheduled = {(s.composite.uid, s.service.name): s
                          for s in self.tree.services.services}
        self.composites = {uid for uid, _ in self.scheduled}

    def replay(self, log: list[Event]) -> tuple[Counter[str], Counter[str]]:
        """(a) and (d) on the log; returns activations and deactivations per composite."""
        started: Counter[str] = Counter()
        stopped: Counter[str] = Counter()
        for event, uid, name, time in log:
            key = (uid, name)
            timing = self.scheduled[key].timing
            if key in self.raised:
                assert event == "on_deactivate", f"{key} raised and was not stopped: {event}"
                self.raised.discard(key)
            probe = self.scheduled[key].service
            assert isinstance(probe, Probe)
            if event == probe.fail:
                self.calls[key] += 1
                if self.calls[key] > probe.fail_after and event != "on_deactivate":
                    self.raised.add(key)
            if event == "on_activate":
                assert key not in self.open, f"{key} activated twice"
                self.open[key] = time
                self.failed.discard(key)
                self.last_run.pop(key, None)
                started[uid] += 1
            elif event == "run":
                assert key in self.open, f"{key} ran while inactive"
                previous = self.last_run.get(key, self.open[key])
                gap = time - previous
                assert gap <= timing.interval + timing.deviation + EPSILON, (key, gap)
                if key in self.last_run and timing.restart_on_activation:
                    assert gap >= timing.interval - timing.deviation - EPSILON, (key, gap)
                self.last_run[key] = time
            else:
                assert event == "on_deactivate", event
                assert key in self.open, f"{key} deactivated while inactive"
                del self.open[key]
                stopped[uid] += 1
                if self.tree.by_uid[uid].status is RUNNING:  # it raised: stopped early
                    self.failed.add(key)
        return started, stopped

    def services_of(self, uid: str) -> list[ScheduledService]:
        return [s for (composite, _), s in self.scheduled.items() if composite == uid]

    def check(self, log: list[Event], ended: set[str]) -> None:
        """(b) and (c) after a tick or a halt; ``ended``: composites halted in it."""
        previously = self.active
        was_open = set(self.open)
        started, stopped = self.replay(log)
        now = {uid for uid in self.composites if self.tree.by_uid[uid].status is RUNNING}
        for uid in self.composites:
            services = self.services_of(uid)
            began = uid in now and (uid not in previously or uid in ended)
            finished = uid in previously and (uid not in now or uid in ended)
            assert started[uid] == (len(services) if began else 0), (uid, started[uid])
            closing = sum(1 for s in services if (uid, s.service.name) in was_open)
            if finished:
                # every service open before the step closes once (and a new one may too)
                assert stopped[uid] >= closing, (uid, stopped[uid], closing)
            elif not began:
                failures = sum(1 for s in services if (uid, s.service.name) in self.failed)
                assert stopped[uid] <= failures, (uid, stopped[uid])
        assert not self.raised, f"raised and not stopped: {self.raised}"
        expected = {key for key in self.scheduled if key[0] in now} - self.failed
        assert set(self.open) == expected, (set(self.open), expected)
        running = {(s.composite.uid, s.service.name) for s in self.scheduled.values() if s.active}
        assert running == expected
        self.active = now

    def step(self, seconds: float) -> None:
        advance(self.tree, seconds)
        self.replay_between(service_log(self.tree))
        snapshot = self.tree.tick()
        self.check(service_log(self.tree), set(snapshot.halted))

    def replay_between(self, log: list[Event]) -> None:
        """Between ticks only runs happen, and failures stop what raised."""
        before = set(self.open)
        started, _ = self.replay(log)
        assert not started
        assert set(self.open) <= before

    def halt(self) -> None:
        """(e): tree.halt() closes every open activation once."""
        halted = {node.uid for node in self.tree.halt()}
        self.check(service_log(self.tree), halted)
        assert self.open == {} and self.active == set()
        assert self.tree.services is not None and self.tree.services.next_due() == float("inf")


SETTINGS = settings(max_examples=300, deadline=None,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])


@SETTINGS
@given(spec=serviced_trees().filter(lambda spec: "services" in repr(spec)), steps=operations)
def test_services_start_and_stop_once_per_activation_on_random_trees(
        spec: N, steps: list[float]) -> None:
    tree = tree_from(spec, services=probe_registry(), resources={"service_log": []})
    checker = ServiceChecker(tree)
    for step in steps:
        if step == HALT:
            checker.halt()
        else:
            checker.step(step)
    checker.halt()
    tree.halt()
    assert service_log(tree) == []
