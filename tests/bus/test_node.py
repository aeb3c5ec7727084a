"""Nodes in one process: in-process delivery, latching, services, parameters, shutdown."""

from __future__ import annotations

import logging
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest

from cyborg.bus import (
    BusConfig,
    Context,
    MessageValueError,
    Node,
    Qos,
    ServiceError,
    ServiceTimeoutError,
    new_message,
    to_plain,
)


@pytest.fixture
def bus() -> Iterator[Context]:
    context = Context(BusConfig.isolated())
    yield context
    context.close()


def wait_for(predicate: Any, timeout: float = 5.0) -> bool:
    deadline = time.monotonic() + timeout
    while not predicate() and time.monotonic() < deadline:
        time.sleep(0.005)
    return bool(predicate())


def image(bus: Context, value: int = 7) -> Any:
    message = new_message(bus.types, "sensor_msgs/msg/Image",
                          {"height": 2, "width": 2, "encoding": "mono8", "step": 2})
    message.data = np.full(4, value, dtype=np.uint8)
    return message


def test_in_process_delivery_shares_arrays_read_only(bus: Context) -> None:
    camera, first, second = (Node(n, context=bus) for n in ("camera", "first", "second"))
    got_first: list[Any] = []
    got_second: list[Any] = []

    def vandal(message: Any) -> None:
        message.header.frame_id = "changed by first"
        with pytest.raises(ValueError, match="read-only"):
            message.data[0] = 99
        got_first.append(message)
    first.create_subscription("image", "sensor_msgs/msg/Image", vandal)
    second.create_subscription("image", "sensor_msgs/msg/Image", got_second.append)
    publisher = camera.create_publisher("image", "sensor_msgs/msg/Image")
    assert publisher.subscription_count() == 2
    sent = image(bus)
    sent.header.frame_id = "camera"
    publisher.publish(sent)
    assert wait_for(lambda: got_first and got_second)
    assert got_second[0].header.frame_id == "camera"
    assert np.shares_memory(got_second[0].data, sent.data)  # not copied, not serialised
    assert got_second[0].data.tolist() == [7, 7, 7, 7]
    assert sent.data.flags.writeable  # the publisher's own array is left alone


def test_publish_checks_the_type(bus: Context) -> None:
    node = Node("talker", context=bus)
    publisher = node.create_publisher("chatter", "std_msgs/msg/String")
    with pytest.raises(TypeError, match="publish on /chatter: expected std_msgs/msg/String"):
        publisher.publish(image(bus))
    with pytest.raises(KeyError, match="unknown message type 'std_msgs/msg/Nope'"):
        node.create_publisher("x", "std_msgs/msg/Nope")


def test_latched_in_process_late_subscriber(bus: Context) -> None:
    node = Node("map_server", context=bus)
    string = bus.types.message_class("std_msgs/msg/String")
    latched = node.create_publisher("map_name", "std_msgs/msg/String", Qos.latched())
    volatile = node.create_publisher("chatter", "std_msgs/msg/String")
    latched.publish(string(data="old"))
    latched.publish(string(data="campus"))
    volatile.publish(string(data="gone"))
    late: list[Any] = []
    missed: list[Any] = []
    node.create_subscription("map_name", "std_msgs/msg/String", late.append, Qos.latched())
    node.create_subscription("chatter", "std_msgs/msg/String", missed.append)
    assert wait_for(lambda: late)
    time.sleep(0.05)
    assert [m.data for m in late] == ["campus"] and missed == []


def test_a_raising_callback_is_contained_and_logged_once(
        bus: Context, caplog: pytest.LogCaptureFixture) -> None:
    node = Node("fragile", context=bus)
    seen: list[str] = []

    def callback(message: Any) -> None:
        seen.append(message.data)
        raise RuntimeError(f"bad {message.data}")
    node.create_subscription("chatter", "std_msgs/msg/String", callback)
    publisher = node.create_publisher("chatter", "std_msgs/msg/String")
    string = bus.types.message_class("std_msgs/msg/String")
    with caplog.at_level(logging.ERROR, "cyborg.bus"):
        for text in ("a", "b", "c"):
            publisher.publish(string(data=text))
        assert wait_for(lambda: len(seen) == 3)
    assert node.callbacks.errors == 3
    errors = [r for r in caplog.records if "raised RuntimeError: bad a" in r.getMessage()]
    assert len(errors) == 1 and errors[0].exc_info is not None
    assert "/fragile" in errors[0].getMessage()


def test_keep_last_queue_drops_the_oldest(bus: Context) -> None:
    node = Node("slow", context=bus)
    gate = threading.Event()
    seen: list[str] = []

    def callback(message: Any) -> None:
        gate.wait(5)
        seen.append(message.data)
    node.create_subscription("chatter", "std_msgs/msg/String", callback, Qos(depth=2))
    publisher = node.create_publisher("chatter", "std_msgs/msg/String")
    string = bus.types.message_class("std_msgs/msg/String")
    # "0" is handed over directly and blocks its publishing thread while the node is busy
    first = threading.Thread(target=publisher.publish, args=(string(data="0"),))
    first.start()
    time.sleep(0.05)  # while "0" is being handled, the queue holds at most two more
    for text in "12345":
        publisher.publish(string(data=text))
    gate.set()
    first.join(5)
    assert wait_for(lambda: len(seen) == 3)
    time.sleep(0.05)
    assert seen == ["0", "4", "5"]


def test_in_process_service_and_deferred_reply(bus: Context) -> None:
    node = Node("calc", context=bus)
    response = bus.types.message_class("example_interfaces/srv/AddTwoInts_Response")
    request = bus.types.message_class("example_interfaces/srv/AddTwoInts_Request")
    node.create_service("add", "example_interfaces/srv/AddTwoInts",
                        lambda r: response(sum=r.a + r.b))

    def later(r: Any, responder: Any) -> None:
        threading.Timer(0.05, responder.reply, [response(sum=r.a * r.b)]).start()
    node.create_service("multiply", "example_interfaces/srv/AddTwoInts", later, deferred=True)
    node.create_service("wrong", "example_interfaces/srv/AddTwoInts", lambda r: r)
    client = Node("user", context=bus)
    assert client.create_client("add", "example_interfaces/srv/AddTwoInts").call(
        request(a=40, b=2)).sum == 42
    assert client.create_client("multiply", "example_interfaces/srv/AddTwoInts").call(
        request(a=6, b=7)).sum == 42
    with pytest.raises(ServiceError, match="returned example_interfaces__srv__AddTwoInts_Req"):
        client.create_client("wrong", "example_interfaces/srv/AddTwoInts").call(request(a=1, b=2))
    with pytest.raises(TypeError, match="expected example_interfaces/srv/AddTwoInts_Request"):
        client.create_client("add", "example_interfaces/srv/AddTwoInts").call(response(sum=1))


def test_parameters_in_process(bus: Context) -> None:
    node = Node("detector", context=bus, parameters={"confidence_threshold": 0.8})
    assert node.parameters.declare("confidence_threshold", 0.5, limits=(0.0, 1.0)) == 0.8
    node.parameters.declare("model", "yolox_nano", read_only=True)
    node.parameters.declare("classes", ["person"])
    changes: list[dict[str, Any]] = []
    node.parameters.on_change(changes.append)

    def refuse_zero(change: dict[str, Any]) -> None:
        if change.get("confidence_threshold") == 0:
            raise ValueError("zero would keep every box")
    node.parameters.on_set(refuse_zero)
    node.parameters.set({"confidence_threshold": 1, "classes": []})
    assert node.parameters["confidence_threshold"] == 1.0  # an int is taken for a float
    assert changes == [{"confidence_threshold": 1.0, "classes": []}]
    for change, error in (({"model": "other"}, "read-only"),
                          ({"confidence_threshold": 0}, "zero would keep every box"),
                          ({"confidence_threshold": 2.0}, r"outside \[0, 1\]"),
                          ({"classes": "person"}, "is a string array, not a string"),
                          ({"nope": 1}, "has no parameter 'nope'")):
        with pytest.raises(ValueError, match=error):
            node.parameters.set(change)
    assert node.parameters["confidence_threshold"] == 1.0 and len(changes) == 1
    with pytest.raises(ValueError, match="already declared"):
        node.parameters.declare("model", "x")


def test_in_process_delivery_keeps_one_callback_at_a_time(bus: Context) -> None:
    node = Node("counter", context=bus)
    running = [0]
    overlaps: list[int] = []
    seen: list[str] = []

    def callback(message: Any) -> None:
        running[0] += 1
        overlaps.append(running[0])
        time.sleep(0.001)
        seen.append(message.data)
        running[0] -= 1
    node.create_subscription("chatter", "std_msgs/msg/String", callback, Qos(depth=1000))
    string = bus.types.message_class("std_msgs/msg/String")
    publishers = [Node(f"talker{i}", context=bus).create_publisher(
        "/chatter", "std_msgs/msg/String") for i in range(4)]
    threads = [threading.Thread(target=lambda p=p: [p.publish(string(data="x"))
                                                    for _ in range(25)])
               for p in publishers]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(10)
    assert wait_for(lambda: len(seen) == 100)
    assert set(overlaps) == {1}


def test_timer_runs_on_the_node_thread(bus: Context) -> None:
    node = Node("ticker", context=bus)
    threads: list[str] = []
    timer = node.create_timer(0.01, lambda: threads.append(threading.current_thread().name))
    assert wait_for(lambda: len(threads) >= 3)
    timer.cancel()
    assert set(threads) == {"cyborg-node/ticker"}
    with pytest.raises(ValueError, match="positive"):
        node.create_timer(0, lambda: None)


def test_names_are_checked() -> None:
    with Context(BusConfig.isolated()) as bus:
        with pytest.raises(ValueError, match="node name '1abc'"):
            Node("1abc", context=bus)
        with pytest.raises(ValueError, match="namespace '/ro bot'"):
            Node("ok", namespace="ro bot", context=bus)


def test_close_leaves_no_threads_behind() -> None:
    before = {t.name for t in threading.enumerate()}
    bus = Context(BusConfig.isolated())
    node = Node("busy", context=bus)
    node.create_timer(0.01, lambda: None)
    node.create_subscription("chatter", "std_msgs/msg/String", lambda m: None)
    client = node.create_client("add", "example_interfaces/srv/AddTwoInts")
    request = bus.types.message_class("example_interfaces/srv/AddTwoInts_Request")
    with pytest.raises(ServiceError):
        client.call_async(request(a=0, b=0), timeout=0.2).result(5)
    bus.close()
    bus.close()  # twice is fine
    assert wait_for(lambda: not [t for t in threading.enumerate() if t.is_alive()
                                 and t.name.startswith("cyborg") and t.name not in before])
    with pytest.raises(RuntimeError, match="destroyed"):
        node.create_publisher("x", "std_msgs/msg/String")


def test_plain_data_conversion(bus: Context) -> None:
    twist = new_message(bus.types, "geometry_msgs/msg/Twist", {"linear": {"x": 0.2}})
    assert to_plain(twist) == {"linear": {"x": 0.2, "y": 0.0, "z": 0.0},
                               "angular": {"x": 0.0, "y": 0.0, "z": 0.0}}
    uuid = new_message(bus.types, "unique_identifier_msgs/msg/UUID")
    assert uuid.uuid.tolist() == [0] * 16
    for data, error in (({"linear": {"w": 1}}, "linear.w: geometry_msgs/msg/Vector3 has no"),
                        ({"linear": {"x": "fast"}}, "linear.x: expected a number"),
                        ({"linear": 3}, "linear: expected a mapping")):
        with pytest.raises(MessageValueError, match=error):
            new_message(bus.types, "geometry_msgs/msg/Twist", data)
    with pytest.raises(MessageValueError, match=r"uuid: expected 16 items, got 2"):
        new_message(bus.types, "unique_identifier_msgs/msg/UUID", {"uuid": [1, 2]})
    with pytest.raises(MessageValueError, match="300 is out of range for uint8"):
        new_message(bus.types, "std_msgs/msg/UInt8", {"data": 300})


def test_a_program_that_forgets_to_close_still_exits() -> None:
    script = ("from cyborg.bus import BusConfig, Context, Node\n"
              "context = Context(BusConfig.isolated())\n"
              "node = Node('forgetful', context=context)\n"
              "node.create_publisher('chatter', 'std_msgs/msg/String')\n"
              "node.create_timer(0.01, lambda: None)\n"
              "print('done', flush=True)\n")
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                            timeout=20)
    assert result.returncode == 0 and result.stdout == "done\n", result.stderr


def test_a_call_without_reply_times_out(bus: Context) -> None:
    node = Node("silent", context=bus)
    node.create_service("never", "std_srvs/srv/Trigger", lambda request, responder: None,
                        deferred=True)
    client = node.create_client("never", "std_srvs/srv/Trigger")
    request = bus.types.message_class("std_srvs/srv/Trigger_Request")
    started = time.monotonic()
    with pytest.raises(ServiceTimeoutError, match=r"/never: no reply within 0.3 s"):
        client.call(request(structure_needs_at_least_one_member=0), timeout=0.3)
    assert 0.25 < time.monotonic() - started < 3


def test_detections_and_parameter_services_are_registered(bus: Context) -> None:
    detections = new_message(bus.types, "vision_msgs/msg/Detection2DArray", {"detections": [
        {"results": [{"hypothesis": {"class_id": "person", "score": 0.9}}],
         "bbox": {"center": {"position": {"x": 320.0, "y": 240.0}}, "size_x": 50.0,
                  "size_y": 120.0}}]})
    data = bus.types.serialize(detections, "vision_msgs/msg/Detection2DArray")
    back = bus.types.deserialize(data, "vision_msgs/msg/Detection2DArray")
    assert to_plain(back) == to_plain(detections)
    for name in ("rcl_interfaces/srv/GetParameters", "action_msgs/srv/CancelGoal",
                 "cyborg_msgs/action/MoveToGoal"):
        assert bus.types.hash(name).startswith("RIHS01_")
