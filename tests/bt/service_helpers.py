"""A scripted service for the tests of services: it logs its lifecycle and can be told to raise.

`Probe` appends ``(event, composite uid, service name, time)`` to the list in the tree's
resources under ``"service_log"`` (`LOG`); its ``fail`` option names the method that raises
(``on_activate``, ``run`` or ``on_deactivate``), ``fail_after`` how many calls of it succeed
first.
"""

from __future__ import annotations

from typing import Any

from cyborg.bt import ManualClock, Service, ServiceBoard, ServiceRegistry, Tree
from tests.builders import N, tree_from

LOG = "service_log"

Event = tuple[str, str, str, float]
"""(event, composite uid, service name, tree-clock time)."""


class Probe(Service):
    """Logs on_activate / run / on_deactivate; writes ``<key>`` = how many runs it made."""

    def __init__(self, key: str = "probe", fail: str = "", fail_after: int = 0) -> None:
        self.key = key
        self.fail = fail
        self.fail_after = fail_after
        self.calls = 0

    def _log(self, event: str, board: ServiceBoard) -> None:
        board.resources[LOG].append((event, self.composite_uid, self.name, board.now))
        if event == self.fail:
            self.calls += 1
            if self.calls > self.fail_after:
                raise RuntimeError(f"{self.name} told to fail in {event}")

    def on_activate(self, blackboard: ServiceBoard) -> None:
        self._log("on_activate", blackboard)

    def run(self, blackboard: ServiceBoard) -> None:
        blackboard[self.key] = blackboard.get(self.key, 0) + 1
        self._log("run", blackboard)

    def on_deactivate(self, blackboard: ServiceBoard) -> None:
        self._log("on_deactivate", blackboard)


class OtherProbe(Probe):
    """The same as Probe under another name, for two services on one composite."""


def probe_registry() -> ServiceRegistry:
    services = ServiceRegistry()
    services.add(Probe)
    services.add(OtherProbe)
    return services


def probe_tree(spec: N, clock: ManualClock | None = None, **resources: Any) -> Tree:
    """A tree of `spec` that knows the probes, with an empty service log."""
    return tree_from(spec, clock=clock, services=probe_registry(),
                     resources={LOG: [], **resources})


def service_log(tree: Tree) -> list[Event]:
    """The probes' log so far, then cleared."""
    log: list[Event] = tree.blackboard.resources[LOG]
    copy = list(log)
    log.clear()
    return copy


def advance(tree: Tree, seconds: float) -> None:
    """Moves the tree's manual clock on by `seconds`, running services when due, as the
    TickLoop does between ticks."""
    clock = tree.clock
    assert isinstance(clock, ManualClock)
    end = clock.now() + seconds
    services = tree.services
    while services is not None and services.next_due() <= end:
        clock.set(max(clock.now(), services.next_due()))
        services.run_due(clock.now())
    clock.set(end)
