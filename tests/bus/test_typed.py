"""Typed messages (issue 20, item 2): classes imported once, endpoints generic in them.

What mypy makes of it is in ``test_bus_typed_mypy.py``; how the classes are generated, in
``test_bus_codegen.py``.
"""

from __future__ import annotations

import threading
from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest

from cyborg.bus import (
    ActionClient,
    ActionServer,
    BusConfig,
    Context,
    GoalStatus,
    Node,
    Publisher,
    ServerGoal,
    ServiceClient,
    Subscription,
    action_client,
)
from cyborg.bus.codegen import TypesFromFiles
from cyborg.bus.msgs.builtin_interfaces.msg import Time
from cyborg.bus.msgs.cyborg_msgs.action import (
    MoveToGoal,
    MoveToGoal_Feedback,
    MoveToGoal_Goal,
    MoveToGoal_Result,
)
from cyborg.bus.msgs.cyborg_msgs.msg import BatteryStatus
from cyborg.bus.msgs.geometry_msgs.msg import Pose2D
from cyborg.bus.msgs.std_msgs.msg import Header, String
from cyborg.bus.msgs.std_srvs.srv import SetBool, SetBool_Request, SetBool_Response
from cyborg.bus.wire import Attachment
from tests.bus.bus_peer import linked_contexts, wait_for


@pytest.fixture
def bus() -> Iterator[Context]:
    context = Context(BusConfig.isolated())
    yield context
    context.close()


def test_a_publisher_and_subscription_made_from_a_class(bus: Context) -> None:
    talker, listener = Node("talker", context=bus), Node("listener", context=bus)
    got: list[String] = []
    subscription: Subscription[String] = listener.create_subscription("chatter", String,
                                                                      got.append)
    publisher: Publisher[String] = talker.create_publisher("chatter", String)
    assert publisher.type_name == subscription.type_name == "std_msgs/msg/String"
    publisher.publish(String(data="hello"))
    assert wait_for(lambda: [m.data for m in got] == ["hello"])
    assert isinstance(got[0], String)


def test_the_callback_gets_the_attachment_with_info(bus: Context) -> None:
    talker, listener = Node("talker", context=bus), Node("listener", context=bus)
    got: list[tuple[str, Attachment | None]] = []
    listener.create_subscription("chatter", String, lambda m, info: got.append((m.data, info)),
                                 with_info=True)
    talker.create_publisher("chatter", String).publish(String(data="x"))
    assert wait_for(lambda: len(got) == 1)
    assert got[0][1] is not None and got[0][1].sequence == 1


def test_type_names_still_work_and_give_the_same_classes(bus: Context) -> None:
    node = Node("talker", context=bus)
    by_name = node.create_publisher("a", "cyborg_msgs/msg/BatteryStatus")
    by_class = node.create_publisher("b", BatteryStatus)
    assert by_name.type_name == by_class.type_name
    assert bus.types.message_class("cyborg_msgs/msg/BatteryStatus") is BatteryStatus
    assert bus.types.message_class("std_msgs/msg/String") is String


def test_a_class_the_store_does_not_use_is_refused(bus: Context) -> None:
    node = Node("talker", context=bus)
    impostor = TypesFromFiles().message_class("cyborg_msgs/msg/BatteryStatus")  # rosbags' own
    assert impostor is not BatteryStatus
    with pytest.raises(TypeError, match="not the class of cyborg_msgs/msg/BatteryStatus here"):
        node.create_publisher("battery", impostor)
    with pytest.raises(TypeError, match="not a message class"):
        node.create_publisher("battery", int)


def _battery(percent: float) -> BatteryStatus:
    return BatteryStatus(header=Header(stamp=Time(sec=1, nanosec=2), frame_id="base"),
                         charging_state=BatteryStatus.CHARGING_FLOAT, charge_percent=percent,
                         voltage=12.5, charging=True, dock_state=BatteryStatus.DOCK_DOCKED)


def test_decoded_messages_are_instances_of_the_generated_classes() -> None:
    with linked_contexts() as (here, there):
        got: list[BatteryStatus] = []
        Node("listener", context=here).create_subscription("battery", BatteryStatus, got.append)
        publisher = Node("robot", context=there).create_publisher("battery", BatteryStatus)
        assert wait_for(lambda: publisher.subscription_count() == 1, 10)
        publisher.publish(_battery(80.0))
        assert wait_for(lambda: got, 10)
    assert type(got[0]) is BatteryStatus  # decoded from CDR, not handed over
    assert got[0].charge_percent == pytest.approx(80.0)
    assert got[0].dock_state == "DOCKED"


def test_cdr_is_the_same_with_the_generated_classes(bus: Context) -> None:
    types = bus.types
    message = _battery(42.0)
    raw = types.serialize(message, "cyborg_msgs/msg/BatteryStatus")
    assert type(types.deserialize(raw, "cyborg_msgs/msg/BatteryStatus")) is BatteryStatus
    rosbags_made = TypesFromFiles()
    same = rosbags_made.message_class("cyborg_msgs/msg/BatteryStatus")(
        **{name: getattr(message, name) for name in (
            "header", "charging_state", "charge_percent", "voltage", "charging", "dock_state")})
    assert bytes(rosbags_made.serialize(same, "cyborg_msgs/msg/BatteryStatus")) == bytes(raw)


def test_a_typed_service(bus: Context) -> None:
    server, user = Node("robot", context=bus), Node("user", context=bus)

    def enable(request: SetBool_Request) -> SetBool_Response:
        return SetBool.Response(success=request.data, message="on" if request.data else "off")
    server.create_service("enable", SetBool, enable)
    client: ServiceClient[SetBool_Request, SetBool_Response] = user.create_client(
        "enable", SetBool)
    response = client.call(SetBool.Request(data=True))
    assert isinstance(response, SetBool_Response)
    assert (response.success, response.message) == (True, "on")

    def later(request: SetBool_Request, responder: Any) -> None:
        threading.Timer(0.01, responder.reply,
                        [SetBool.Response(success=False, message="later")]).start()
    server.create_service("defer", SetBool, later, deferred=True)
    assert user.create_client("defer", SetBool).call(SetBool.Request(data=True)).message == \
        "later"


def test_a_typed_action(bus: Context) -> None:
    robot, user = Node("robot", context=bus), Node("user", context=bus)
    sent = threading.Event()

    def move(goal: ServerGoal[MoveToGoal_Goal, MoveToGoal_Feedback]) -> MoveToGoal_Result:
        sent.wait(5)  # the client knows the goal: its feedback is not dropped
        goal.publish_feedback(MoveToGoal.Feedback(current_pose=goal.request.pose,
                                                  distance_remaining=0.0))
        return MoveToGoal.Result(outcome=MoveToGoal_Result.SUCCEEDED,
                                 message=goal.request.goal_name)
    server: ActionServer[MoveToGoal_Goal, MoveToGoal_Result, MoveToGoal_Feedback] = \
        robot.create_action_server("move", MoveToGoal, move)
    assert server.action_type == "cyborg_msgs/action/MoveToGoal"
    client: ActionClient[MoveToGoal_Goal, MoveToGoal_Result, MoveToGoal_Feedback] = \
        user.create_action_client("move", MoveToGoal)
    assert client.wait_for_server(5)
    feedback: list[MoveToGoal_Feedback] = []
    goal = client.send_goal(MoveToGoal.Goal(goal_name="kitchen", pose=Pose2D(x=1.0, y=2.0,
                                                                             theta=0.0),
                                            use_heading=False), feedback=feedback.append)
    sent.set()
    status, result = goal.result(timeout=10)
    assert status is GoalStatus.SUCCEEDED
    assert isinstance(result, MoveToGoal_Result)
    assert (result.outcome, result.message) == (MoveToGoal_Result.SUCCEEDED, "kitchen")
    assert wait_for(lambda: feedback)
    assert isinstance(feedback[0], MoveToGoal_Feedback)
    assert np.isclose(feedback[0].current_pose.y, 2.0)


def test_a_result_whose_request_was_lost_is_asked_for_again(
        bus: Context, monkeypatch: pytest.MonkeyPatch) -> None:
    """The server holds a get_result request open until the goal ends; one lost on the way
    (here: the server drops the first) no longer leaves the goal without a result for an hour:
    the client asks again after RESULT_WAIT seconds and gets the kept result."""
    monkeypatch.setattr(action_client, "RESULT_WAIT", 0.5)
    answer, dropped = ActionServer._on_get_result, list[Any]()

    def lose_the_first(server: Any, request: Any, responder: Any) -> None:
        if not dropped:
            dropped.append(responder)  # never answered
            return
        answer(server, request, responder)

    monkeypatch.setattr(ActionServer, "_on_get_result", lose_the_first)
    robot, user = Node("robot", context=bus), Node("user", context=bus)
    robot.create_action_server("move", MoveToGoal, lambda goal: MoveToGoal.Result(
        outcome=MoveToGoal_Result.SUCCEEDED, message=goal.request.goal_name))
    client = user.create_action_client("move", MoveToGoal)
    assert client.wait_for_server(5)
    goal = client.send_goal(MoveToGoal.Goal(
        goal_name="kitchen", pose=Pose2D(x=0.0, y=0.0, theta=0.0), use_heading=False))
    status, result = goal.result(timeout=10)
    assert dropped, "the first request was lost"
    assert status is GoalStatus.SUCCEEDED and result.message == "kitchen"
