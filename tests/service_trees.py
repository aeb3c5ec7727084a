"""Trees whose composites carry services, for the tests of the runner, the monitor and the page:
`Counter` writes how often it ran, `Broken` raises; `sequence_with` is a Sequence carrying the
services given over a leaf that runs for ever, so they stay active."""

from __future__ import annotations

from typing import Any

from cyborg.bt import Service, ServiceBoard, ServiceRegistry
from cyborg.runner.tree_runner import TreeRunnerNode


class Counter(Service):
    """Writes how many times it ran under ``key``."""

    interval = 0.05

    def __init__(self, key: str = "count") -> None:
        self.key = key

    def run(self, blackboard: ServiceBoard) -> None:
        blackboard[self.key] = blackboard.get(self.key, 0) + 1


class Broken(Service):
    """Raises on its first run."""

    interval = 0.05

    def run(self, blackboard: ServiceBoard) -> None:
        raise RuntimeError("the sensor is unplugged")


def registry() -> ServiceRegistry:
    """The services above, by their class names."""
    services = ServiceRegistry()
    services.add(Counter)
    services.add(Broken)
    return services


def sequence_with(services: str) -> dict[str, Any]:
    """A Sequence carrying ``services`` over a leaf that runs for ever (`write_tree`'s form)."""
    return {"name": "Sequence", "props": {"services": services}, "children": [{"name": "Runner"}]}


def sequence_of(runner: TreeRunnerNode) -> str:
    """The id of the runner's Sequence, the composite that carries the services."""
    return next(node.uid for node in runner.tree.nodes if node.name == "Sequence")
