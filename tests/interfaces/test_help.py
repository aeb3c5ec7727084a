"""The call for help: its JSON both ways, its errors, and BusRobot calling on the bus."""

from __future__ import annotations

import json
import threading

import pytest

from cyborg.bus import BusConfig, Context, Node
from cyborg.bus.msgs.std_msgs.msg import String
from cyborg.interfaces.help import HELP, SCHEMA, HelpCall, help_text, read_help
from cyborg.robot.bus_robot import BusRobot
from tests.running_system import wait_until


def test_a_call_goes_through_its_text_unchanged() -> None:
    call = HelpCall("/robot2", "battery critical", (1.5, -2.0, 0.25), 7.5, 1234.5)
    text = help_text(call)
    data = json.loads(text.data)
    assert data["schema"] == SCHEMA
    assert data["pose"] == {"x": 1.5, "y": -2.0, "theta": 0.25}
    assert read_help(text) == call
    unknown = HelpCall("/cyborg", "lost", None, None, 0.0)
    assert read_help(help_text(unknown)) == unknown


@pytest.mark.parametrize(("data", "field"), [
    ("not json", "JSON"),
    ("[1]", "JSON object"),
    ('{"schema": "other/1"}', "schema"),
    (json.dumps({"schema": SCHEMA, "robot": 3, "reason": ""}), "robot"),
    (json.dumps({"schema": SCHEMA, "robot": "/r", "reason": "x", "pose": {"x": 1},
                 "time": 0}), "pose"),
    (json.dumps({"schema": SCHEMA, "robot": "/r", "reason": "x", "pose": None,
                 "battery": "low", "time": 0}), "battery"),
    (json.dumps({"schema": SCHEMA, "robot": "/r", "reason": "x", "pose": None,
                 "battery": None, "time": True}), "time"),
])
def test_a_text_that_is_not_a_call_names_what_is_wrong(data: str, field: str) -> None:
    with pytest.raises(ValueError, match=field):
        read_help(String(data=data))


def test_the_bus_robot_calls_for_help_under_its_namespace() -> None:
    with Context(BusConfig.isolated()) as bus:
        robot = BusRobot(Node("bt_robot", "/robot2/bt", context=bus), "/robot2")
        listener = Node("listener", "/test", context=bus)
        heard: list[HelpCall] = []
        lock = threading.Lock()

        def hear(message: String) -> None:
            with lock:
                heard.append(read_help(message))

        HELP.subscription(listener, hear, "/robot2")
        wait_until(lambda: robot._help.subscription_count() > 0, 10.0, "the listener")
        robot.call_for_help("stopped: battery critical", 42.0)
        wait_until(lambda: bool(heard), 10.0, "the call")
        assert heard[0] == HelpCall("/robot2", "stopped: battery critical", None, None, 42.0)
