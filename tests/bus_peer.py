"""A second process for the bus tests: ``python bus_peer.py ROLE ENDPOINT``.

It joins the router at ENDPOINT, sets up what ROLE says, prints ``ready`` and then lives until
its stdin closes (the test ends) or 60 s pass, so a failing test never leaves it behind.
"""

from __future__ import annotations

import random
import sys
import threading
import time
from typing import Any

import numpy as np
import zenoh

from cyborg.bus import BusConfig, Context, Node, Qos, ServerGoal, new_message
from cyborg.bus.wire import Attachment


def talker(node: Node) -> None:
    publisher = node.create_publisher("chatter", "std_msgs/msg/String")
    message = node.types.message_class("std_msgs/msg/String")

    def run() -> None:
        count = 0
        while True:
            count += 1
            publisher.publish(message(data=f"hello {count}"))
            time.sleep(0.02)
    threading.Thread(target=run, daemon=True).start()


def latched(node: Node) -> None:
    publisher = node.create_publisher("status", "std_msgs/msg/String", Qos.latched())
    message = node.types.message_class("std_msgs/msg/String")
    publisher.publish(message(data="first"))
    publisher.publish(message(data="latest"))


def server(node: Node) -> None:
    response = node.types.message_class("example_interfaces/srv/AddTwoInts_Response")
    node.create_service("add", "example_interfaces/srv/AddTwoInts",
                        lambda request: response(sum=request.a + request.b))

    def fail(request: Any) -> Any:
        raise ValueError(f"cannot add {request.a} and {request.b}")
    node.create_service("fail", "example_interfaces/srv/AddTwoInts", fail)


def action(node: Node) -> None:
    result = node.types.message_class("cyborg_msgs/action/MoveToGoal_Result")

    def execute(goal: ServerGoal) -> Any:
        remaining = 5.0
        while remaining > 0:
            if goal.cancel_requested:
                goal.canceled()
                return result(outcome=3, message="canceled")
            goal.publish_feedback(new_message(
                node.types, "cyborg_msgs/action/MoveToGoal_Feedback",
                {"current_pose": {"x": 5.0 - remaining}, "distance_remaining": remaining}))
            remaining -= 0.25
            time.sleep(0.1)
        return result(outcome=1, message=f"reached {goal.request.goal_name}")
    node.create_action_server("move_to_goal", "cyborg_msgs/action/MoveToGoal", execute)


def params(node: Node) -> None:
    node.parameters.declare("confidence_threshold", 0.5, "detections below are dropped",
                            limits=(0.0, 1.0))
    node.parameters.declare("classes", ["person"], "labels to keep")
    string = node.types.message_class("std_msgs/msg/String")
    changes = node.create_publisher("changes", "std_msgs/msg/String", Qos.latched())
    node.parameters.on_change(lambda c: changes.publish(string(data=repr(sorted(c.items())))))


def garbage(node: Node) -> None:
    """Junk on the chatter key, then one good message, repeatedly."""
    context = node.context
    key = f"{context.domain}/chatter/std_msgs::msg::dds_::String_/" + \
        context.types.hash("std_msgs/msg/String")
    good = node.create_publisher("/chatter", "std_msgs/msg/String")
    string = node.types.message_class("std_msgs/msg/String")
    wrong = context.types.serialize(new_message(context.types, "geometry_msgs/msg/Point",
                                                {"x": 1.0}), "geometry_msgs/msg/Point")
    valid = bytes(context.types.serialize(string(data="truncate me please"),
                                          "std_msgs/msg/String"))
    rng = random.Random(7)

    def run() -> None:
        sequence = 1000
        while True:
            sequence += 1
            attachment = Attachment(sequence, time.time_ns(), bytes(16)).encode()
            try:
                for junk in (bytes(rng.randrange(256) for _ in range(40)), valid[:9],
                             bytes(wrong.obj), b""):
                    context.session.put(key, junk, attachment=attachment)
                context.session.put(key, valid, attachment=b"not an attachment")
                good.publish(string(data="good"))
            except (zenoh.ZError, RuntimeError):  # closing down
                return
            time.sleep(0.02)
    threading.Thread(target=run, daemon=True).start()


def image(node: Node) -> None:
    publisher = node.create_publisher("camera/image", "sensor_msgs/msg/Image")
    types = node.types

    def run() -> None:
        frame = 0
        while True:
            frame += 1
            pixels = np.full(1920 * 1080 * 3, frame % 256, dtype=np.uint8)
            message = new_message(types, "sensor_msgs/msg/Image", {
                "header": {"frame_id": str(frame)}, "height": 1080, "width": 1920,
                "encoding": "bgr8", "step": 5760})
            message.data = pixels
            publisher.publish(message)
            time.sleep(0.05)
    threading.Thread(target=run, daemon=True).start()


def idle(node: Node) -> None:
    """Just a node, to be killed."""


ROLES = {"talker": talker, "latched": latched, "server": server, "action": action,
         "params": params, "garbage": garbage, "image": image, "idle": idle}


def main() -> None:
    role, endpoint = sys.argv[1], sys.argv[2]
    context = Context(BusConfig(connect=(endpoint,)))
    node = Node(f"peer_{role}", namespace="/robot", context=context)
    ROLES[role](node)
    while not (context.session.info.routers_zid() or context.session.info.peers_zid()):
        time.sleep(0.02)
    print("ready", flush=True)
    watchdog = threading.Thread(target=sys.stdin.read, daemon=True)
    watchdog.start()
    watchdog.join(60)
    context.close()


if __name__ == "__main__":
    zenoh.init_log_from_env_or("error")
    main()
