"""A bus with a Foxglove server on it, and publishers of what a robot and a tree runner publish."""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import Any

import pytest

from cyborg.bus import BusConfig, Context, Node, Publisher
from cyborg.foxglove import FoxgloveServer
from tests.foxglove.protocol_client import ProtocolClient


@dataclass
class Served:
    """The bus, a node to publish from, and the Foxglove server serving them."""

    context: Context
    publisher_node: Node
    server: FoxgloveServer

    def client(self, subprotocol: str = "foxglove.websocket.v1", query: str = "",
               headers: dict[str, str] | None = None) -> ProtocolClient:
        return ProtocolClient(f"ws://127.0.0.1:{self.server.port}/{query}", subprotocol,
                              headers)

    def subscriptions(self, topic: str) -> int:
        """Subscriptions on ``topic`` made by the server's node (on the bus graph)."""
        return len(self.subscription_ids(topic))

    def subscription_ids(self, topic: str) -> set[int]:
        """The entity ids of the subscriptions on ``topic`` made by the server's node."""
        node = self.server.node.fq_name
        return {entity.entity_id for entity in self.context.graph.entities()
                if entity.topic == topic and entity.node_name == node
                and entity.kind.name == "SUBSCRIPTION"}


@pytest.fixture
def served() -> Iterator[Served]:
    context = Context(BusConfig.isolated())
    # linger 0: a channel leaves the bus as its last client leaves (test_client_floods lingers)
    server = FoxgloveServer(Node("foxglove", "/cyborg", context=context), port=0, poll=0.05,
                            linger=0.0)
    server.start()
    try:
        yield Served(context, Node("robot", "/cyborg", context=context), server)
    finally:
        server.stop()
        context.close()


class Repeating:
    """Publishes a message again and again (20 Hz) until stopped: a sensor's stream."""

    def __init__(self, publisher: Publisher[Any], make: Callable[[int], Any]) -> None:
        self._stop = threading.Event()
        self.sent: list[Any] = []

        def run() -> None:
            count = 0
            while not self._stop.wait(0.05):
                message = make(count)
                publisher.publish(message)
                self.sent.append(message)
                count += 1
        self._thread = threading.Thread(target=run, daemon=True)
        self._thread.start()

    def stop(self) -> None:
        self._stop.set()
        self._thread.join(5)


def wait_for(condition: Callable[[], object], timeout: float = 30.0) -> bool:
    deadline = time.monotonic() + timeout
    while not condition() and time.monotonic() < deadline:
        time.sleep(0.01)
    return bool(condition())
