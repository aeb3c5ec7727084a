"""``cyborg topic pub --once`` reaches a subscriber in another process every time."""

from __future__ import annotations

import subprocess
import sys
import threading
from collections.abc import Iterator

import pytest

from tests.app.test_bus_cli import on, start_router, stop


@pytest.fixture(scope="module")
def endpoint() -> Iterator[str]:
    address, router = start_router()
    yield address
    stop(router)


def test_pub_once_reaches_a_subscriber_every_time(endpoint: str) -> None:
    """A subscriber listed in the graph may not be matched by Zenoh's routing yet: ``--once``
    waits for both, so none of five single messages is lost (one in three was); with nobody
    listening it says so and publishes anyway."""
    listener = subprocess.Popen(
        [sys.executable, "-m", "cyborg", "topic", "echo", "/events", "std_msgs/msg/String",
         "--count", "5", "--timeout", "60", "--connect", endpoint, "--wait", "0.5"],
        stdout=subprocess.PIPE, text=True)
    try:
        threading.Event().wait(2.5)
        for index in range(5):
            sent = on(endpoint, "topic", "pub", "/events", "std_msgs/msg/String",
                      f"{{data: event {index}}}", "--once")
            assert sent.returncode == 0 and "no subscriber" not in sent.stderr, sent.stderr
        out, _ = listener.communicate(timeout=30)
    finally:
        listener.kill()
    assert [f"data: event {index}" in out for index in range(5)] == [True] * 5, out
    alone = on(endpoint, "topic", "pub", "/nobody_listens", "std_msgs/msg/String",
               "{data: hello}", "--once")
    assert alone.returncode == 0
    assert "no subscriber of /nobody_listens within 3 s; publishing anyway" in alone.stderr
