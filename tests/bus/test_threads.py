"""Which thread runs a subscription's callback: its own node's, never the publisher's.

Issue 20, item 3: in-process delivery used to call the callback on the publisher's thread
whenever the subscribing node was idle (a monitor's tick handling on the tree's tick thread,
inference on the camera's thread). Now that is an opt-in of one subscription (``inline=True``).
"""

from __future__ import annotations

import gc
import threading
import time
import weakref
from collections.abc import Callable, Iterator

import pytest

from cyborg.bus import BusConfig, Context, Node, Publisher, Qos
from cyborg.bus.msgs.std_msgs.msg import String
from tests.bus.bus_peer import wait_for


@pytest.fixture
def bus() -> Iterator[Context]:
    context = Context(BusConfig.isolated())
    yield context
    context.close()


def _publish_from(thread_name: str, publish: Callable[[], object]) -> threading.Thread:
    """Run ``publish`` on a thread of that name (a tree's tick thread, a camera's) and wait."""
    thread = threading.Thread(target=publish, name=thread_name)
    thread.start()
    thread.join(5)
    return thread


def test_an_in_process_callback_runs_on_the_subscriber_nodes_thread(bus: Context) -> None:
    tree, monitor = Node("tree", context=bus), Node("monitor", context=bus)
    ran: list[tuple[threading.Thread, bool]] = []
    monitor.create_subscription(
        "ticks", String,
        lambda _m: ran.append((threading.current_thread(), monitor.callbacks.in_thread())))
    ticks = tree.create_publisher("ticks", String)
    publishers = []
    for count in range(1, 6):  # one at a time, the monitor idle each time: the old inline case
        publishers.append(_publish_from("tick-thread", lambda: ticks.publish(String(data="t"))))
        assert wait_for(lambda: len(ran) == count)  # noqa: B023 (waited for here)
    assert all(in_node for _thread, in_node in ran)
    assert {thread.name for thread, _in_node in ran} == {"cyborg-node/monitor"}
    assert not any(thread is publisher for thread, _ in ran for publisher in publishers)


def test_a_publisher_never_waits_for_a_slow_in_process_callback(bus: Context) -> None:
    camera, detector = Node("camera", context=bus), Node("detector", context=bus)
    release, done = threading.Event(), threading.Event()

    def inference(_message: String) -> None:
        release.wait(5)
        done.set()
    detector.create_subscription("image", String, inference)
    image = camera.create_publisher("image", String)
    started = time.monotonic()
    image.publish(String(data="frame"))
    assert time.monotonic() - started < 1.0, "publish ran the subscriber's callback"
    assert not done.is_set()
    release.set()
    assert done.wait(5)


def test_a_latched_message_reaches_a_new_subscription_on_its_nodes_thread(
        bus: Context) -> None:
    Node("map_server", context=bus).create_publisher(
        "map", String, Qos.latched()).publish(String(data="map"))
    viewer = Node("viewer", context=bus)
    ran: list[str] = []
    viewer.create_subscription("map", String,
                               lambda m: ran.append(threading.current_thread().name),
                               Qos.latched())
    assert wait_for(lambda: ran == ["cyborg-node/viewer"])


def test_a_routed_subscription_runs_on_the_thread_it_was_routed_to(bus: Context) -> None:
    node, talker = Node("listener", context=bus), Node("talker", context=bus)
    ran: list[str] = []
    subscription = node.create_subscription(
        "chatter", String, lambda m: ran.append(threading.current_thread().name))
    node.callbacks.route(subscription, node.callback_thread("fast"))
    talker.create_publisher("chatter", String).publish(String(data="x"))
    assert wait_for(lambda: ran == ["cyborg-node/listener[fast]"])


def test_inline_opt_in_runs_on_the_publishers_thread_while_the_node_is_idle(
        bus: Context) -> None:
    camera, viewer = Node("camera", context=bus), Node("viewer", context=bus)
    ran: list[tuple[str, str]] = []
    viewer.create_subscription("image", String,
                               lambda m: ran.append((m.data, threading.current_thread().name)),
                               inline=True)
    image = camera.create_publisher("image", String)
    _publish_from("camera-thread", lambda: image.publish(String(data="a")))
    assert ran == [("a", "camera-thread")]  # called during publish, on the camera's thread


def test_inline_opt_in_queues_while_the_node_is_busy_and_keeps_the_order(
        bus: Context) -> None:
    camera, viewer = Node("camera", context=bus), Node("viewer", context=bus)
    busy, release = threading.Event(), threading.Event()
    ran: list[tuple[str, str]] = []

    def block() -> None:
        busy.set()
        release.wait(5)
    viewer.create_subscription("image", String,
                               lambda m: ran.append((m.data, threading.current_thread().name)),
                               Qos(depth=10), inline=True)
    image = camera.create_publisher("image", String)
    viewer.callbacks.submit(block)
    assert busy.wait(5)
    _publish_from("camera-thread", lambda: image.publish(String(data="a")))
    release.set()
    assert wait_for(lambda: len(ran) == 1)

    def two() -> None:
        image.publish(String(data="b"))
        image.publish(String(data="c"))
    _publish_from("camera-thread", two)
    assert wait_for(lambda: len(ran) == 3)
    assert [data for data, _thread in ran] == ["a", "b", "c"]
    assert ran[0][1] == "cyborg-node/viewer"  # the node was busy: queued to its thread


def test_destroying_a_publisher_while_another_thread_publishes_on_it(bus: Context) -> None:
    """Callbacks now publish from their nodes' threads while, say, the main thread tears the
    nodes down: destroy must wait for a publish in progress (Zenoh refuses to undeclare a
    publisher another thread is using) and later publishes must say it was destroyed."""
    def flood(publisher: Publisher[String], started: threading.Event,
              errors: list[str]) -> None:
        started.set()
        try:
            while True:
                publisher.publish(String(data="x"))
        except RuntimeError as exc:
            errors.append(str(exc))
    for attempt in range(20):
        node = Node(f"talker{attempt}", context=bus)
        publisher = node.create_publisher("chatter", String)
        errors: list[str] = []
        started = threading.Event()
        thread = threading.Thread(target=flood, args=(publisher, started, errors))
        thread.start()
        assert started.wait(5)
        time.sleep(0.001 * (attempt % 5))
        publisher.destroy()  # raised "Already borrowed" now and then before
        thread.join(5)
        assert errors and "the publisher was destroyed" in errors[0], errors
        node.destroy()


def test_flush_waits_until_what_was_queued_has_run(bus: Context) -> None:
    camera, detector = Node("camera", context=bus), Node("detector", context=bus)
    seen: list[str] = []

    def slow(message: String) -> None:
        time.sleep(0.05)
        seen.append(message.data)
    detector.create_subscription("image", String, slow, Qos(depth=10))
    image = camera.create_publisher("image", String)
    for data in "abc":
        image.publish(String(data=data))
    assert detector.callbacks.flush(5)
    assert seen == ["a", "b", "c"]  # a test moving a fake clock may now move it
    errors: list[BaseException] = []

    def on_own_thread() -> None:
        try:
            detector.callbacks.flush()
        except RuntimeError as exc:
            errors.append(exc)
    detector.callbacks.submit(on_own_thread)
    assert detector.callbacks.flush(5)
    assert errors and "would wait forever" in str(errors[0])


def test_a_route_once_forgotten_no_longer_keeps_its_owner(bus: Context) -> None:
    node = Node("relay", context=bus)
    own = node.callback_thread("own")

    class Owner:
        def __init__(self) -> None:
            self.threads: list[str] = []

        def run(self) -> None:
            self.threads.append(threading.current_thread().name)
    owner = Owner()
    node.callbacks.route(owner, own)
    node.callbacks.submit(owner.run)
    node.callbacks.unroute(Owner())  # never routed: nothing happens
    assert own.flush(5)
    node.callbacks.unroute(owner)
    node.callbacks.submit(owner.run)
    assert node.callbacks.flush(5)
    assert owner.threads == ["cyborg-node/relay[own]", "cyborg-node/relay"]
    kept = weakref.ref(owner)
    del owner
    gc.collect()
    assert kept() is None  # a destroyed subscription's route held it, its queue, for good
    node.destroy()
