"""The bus between processes on loopback: a router in the test process, peers in subprocesses.

Every wait is bounded; a peer lives at most 60 s even if a test dies.
"""

from __future__ import annotations

import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

from cyborg.bus import (
    ActionError,
    BusConfig,
    Context,
    GoalStatus,
    Node,
    Qos,
    ServiceError,
    new_message,
)
from cyborg.bus.doorbell import supported as doorbell_supported
from cyborg.bus.parameter_client import ParameterClient, ParameterError
from tests.ports import free_port

pytestmark = pytest.mark.heavy
PEER = Path(__file__).with_name("bus_peer.py")


@pytest.fixture(scope="module")
def endpoint() -> Iterator[str]:
    address = f"tcp/127.0.0.1:{free_port()}"
    router = Context(BusConfig.router([address]))
    yield address
    router.close()


@pytest.fixture
def bus(endpoint: str) -> Iterator[Context]:
    context = Context(BusConfig(connect=(endpoint,)))
    yield context
    context.close()


@pytest.fixture
def spawn(endpoint: str) -> Iterator[Callable[[str], subprocess.Popen[str]]]:
    peers: list[subprocess.Popen[str]] = []

    def start(role: str) -> subprocess.Popen[str]:
        peer = subprocess.Popen([sys.executable, str(PEER), role, endpoint], text=True,
                                stdin=subprocess.PIPE, stdout=subprocess.PIPE)
        peers.append(peer)
        assert peer.stdout is not None
        lines: list[str] = []
        reader = threading.Thread(target=lambda: lines.append(peer.stdout.readline()),  # type: ignore[union-attr]
                                  daemon=True)
        reader.start()
        reader.join(20)
        assert lines and lines[0].strip() == "ready", f"peer {role} did not start: {lines}"
        return peer

    yield start
    for peer in peers:
        if peer.poll() is None:
            assert peer.stdin is not None
            peer.stdin.close()
            try:
                peer.wait(10)
            except subprocess.TimeoutExpired:
                peer.kill()
                raise


def collect(node: Node, topic: str, type_name: str, qos: Qos | None = None,
            ) -> tuple[list[Any], threading.Event]:
    received: list[Any] = []
    arrived = threading.Event()

    def keep(message: Any) -> None:
        received.append(message)
        arrived.set()
    node.create_subscription(topic, type_name, keep, qos)
    return received, arrived


def wait_until(predicate: Callable[[], bool], timeout: float) -> bool:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if predicate():
            return True
        time.sleep(0.02)
    return predicate()


def test_publish_subscribe_between_processes(bus: Context, spawn: Any) -> None:
    spawn("talker")
    node = Node("listener", context=bus)
    received, _ = collect(node, "/robot/chatter", "std_msgs/msg/String")
    assert wait_until(lambda: len(received) >= 5, 10)
    numbers = [int(m.data.split()[1]) for m in received[:5]]
    assert numbers == sorted(numbers) and len(set(numbers)) == 5
    assert wait_until(lambda: "/robot/peer_talker" in bus.graph.nodes(), 5)
    assert bus.graph.topics()["/robot/chatter"] == {"std_msgs/msg/String"}


def test_latched_topic_reaches_a_late_subscriber(bus: Context, spawn: Any) -> None:
    spawn("latched")
    time.sleep(0.5)  # the message was published long before we subscribe
    node = Node("late", context=bus)
    received, arrived = collect(node, "/robot/status", "std_msgs/msg/String", Qos.latched())
    assert arrived.wait(10)
    time.sleep(0.3)
    assert [m.data for m in received] == ["latest"]


def test_service_call_and_remote_exception(bus: Context, spawn: Any) -> None:
    spawn("server")
    node = Node("caller", context=bus)
    request = node.types.message_class("example_interfaces/srv/AddTwoInts_Request")
    add = node.create_client("/robot/add", "example_interfaces/srv/AddTwoInts")
    assert add.wait_for_service(10)
    assert add.call(request(a=2, b=40), timeout=5).sum == 42
    assert add.call_async(request(a=-1, b=1)).result(10).sum == 0
    fail = node.create_client("/robot/fail", "example_interfaces/srv/AddTwoInts")
    assert fail.wait_for_service(10)
    with pytest.raises(ServiceError, match=r"/robot/fail failed: ValueError: cannot add 3 and 4"):
        fail.call(request(a=3, b=4), timeout=5)
    missing = node.create_client("/robot/nothing", "example_interfaces/srv/AddTwoInts")
    with pytest.raises(ServiceError, match="not available"):
        missing.call(request(a=1, b=1), timeout=1)


def test_action_feedback_result_and_cancel(bus: Context, spawn: Any) -> None:
    spawn("action")
    node = Node("commander", context=bus)
    client = node.create_action_client("/robot/move_to_goal", "cyborg_msgs/action/MoveToGoal")
    assert client.wait_for_server(10)
    goal_type = "cyborg_msgs/action/MoveToGoal_Goal"
    feedback: list[Any] = []
    goal = client.send_goal(new_message(node.types, goal_type, {"goal_name": "kitchen"}),
                            feedback=feedback.append)
    status, result = goal.result(timeout=10)
    assert status is GoalStatus.SUCCEEDED
    assert (result.outcome, result.message) == (1, "reached kitchen")
    assert wait_until(lambda: len(feedback) >= 5, 2)
    remaining = [f.distance_remaining for f in feedback]
    assert remaining == sorted(remaining, reverse=True)

    second = client.send_goal(new_message(node.types, goal_type, {"goal_name": "dock"}))
    assert wait_until(lambda: second.status is GoalStatus.EXECUTING, 5)
    assert second.cancel()
    status, result = second.result(timeout=10)
    assert status is GoalStatus.CANCELED and result.outcome == 3
    assert not second.cancel()  # already finished: refused


def test_action_server_absent(bus: Context) -> None:
    node = Node("commander", context=bus)
    client = node.create_action_client("/nobody/move", "cyborg_msgs/action/MoveToGoal")
    goal = new_message(node.types, "cyborg_msgs/action/MoveToGoal_Goal")
    with pytest.raises(ActionError, match="/nobody/move"):
        client.send_goal(goal, timeout=1)


def test_parameters_list_get_set_with_callbacks(bus: Context, spawn: Any) -> None:
    spawn("params")
    node = Node("tuner", context=bus)
    changes, changed = collect(node, "/robot/changes", "std_msgs/msg/String", Qos.latched())
    assert wait_until(lambda: "/robot/peer_params" in bus.graph.nodes(), 10)
    client = ParameterClient(node, "/robot/peer_params")
    assert client.wait_for_service(10)
    assert client.names() == ["classes", "confidence_threshold"]
    assert client.get(["confidence_threshold", "classes"]) == {
        "confidence_threshold": 0.5, "classes": ["person"]}
    client.set({"confidence_threshold": 0.7})
    assert client.get(["confidence_threshold"])["confidence_threshold"] == 0.7
    assert changed.wait(5)
    assert changes[-1].data == "[('confidence_threshold', 0.7)]"
    with pytest.raises(ParameterError, match=r"outside \[0, 1\]"):
        client.set({"confidence_threshold": 1.5})
    with pytest.raises(ParameterError, match="is a double, not a string"):
        client.set({"confidence_threshold": "high"})
    with pytest.raises(ParameterError, match="no parameter nope"):
        client.get(["nope"])
    assert client.get(["confidence_threshold"])["confidence_threshold"] == 0.7
    (description,) = client.describe(["confidence_threshold"])
    assert description.description == "detections below are dropped"
    assert description.floating_point_range[0].to_value == 1.0


def test_a_dead_peer_leaves_the_graph_within_two_seconds(bus: Context, spawn: Any) -> None:
    peer = spawn("idle")
    assert wait_until(lambda: "/robot/peer_idle" in bus.graph.nodes(), 10)
    peer.kill()
    killed = time.monotonic()
    assert bus.graph.wait_for(lambda graph: "/robot/peer_idle" not in graph.nodes(), 2.0)
    assert time.monotonic() - killed < 2.0


def test_garbage_is_dropped_and_counted(bus: Context, spawn: Any) -> None:
    node = Node("listener", context=bus)
    received, _ = collect(node, "/chatter", "std_msgs/msg/String")
    spawn("garbage")
    assert wait_until(lambda: sum(bus.dropped.values()) >= 20 and len(received) >= 3, 10)
    assert {m.data for m in received} == {"good"}
    reasons = " ".join(bus.dropped)
    assert "cannot decode std_msgs/msg/String" in reasons
    assert "bad attachment" in reasons


def frame_from_image_peer(bus: Context, spawn: Any, frames: int) -> Any:
    """The last of ``frames`` camera images a spawned peer published, after checking that it
    arrived whole and as a read-only view on the publisher's shared-memory slot."""
    node = Node("viewer", context=bus)
    received, _ = collect(node, "/robot/camera/image", "sensor_msgs/msg/Image",
                          Qos(depth=2))
    spawn("image")
    assert wait_until(lambda: len(received) >= frames, 15)
    frame = received[-1]
    assert frame.data.shape == (1920 * 1080 * 3,)
    assert int(frame.data[0]) == int(frame.header.frame_id) % 256
    assert int(frame.data[-1]) == int(frame.header.frame_id) % 256
    # the pixels are a view on the publisher's shared-memory slot, not a private copy
    assert type(frame.data.base.obj).__name__ == "ndarray"
    assert not frame.data.flags.writeable
    return frame


def test_large_messages_go_through_shared_memory(bus: Context, spawn: Any) -> None:
    frame = frame_from_image_peer(bus, spawn, 5)
    with pytest.raises(ValueError, match="read-only"):
        frame.data[0] = 1
    if doorbell_supported():  # the slot references came by Unix datagram, not through Zenoh
        assert bus.doorbell is not None and bus.doorbell.answered >= 5


def test_without_a_doorbell_slot_references_come_through_zenoh(endpoint: str,
                                                               spawn: Any) -> None:
    with Context(BusConfig(connect=(endpoint,), doorbell=False)) as bus:
        assert bus.doorbell is None
        frame_from_image_peer(bus, spawn, 3)
