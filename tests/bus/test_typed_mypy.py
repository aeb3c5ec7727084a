"""Strict mypy catches a misspelt field where messages cross the bus (issue 20, item 2).

Message classes come from :mod:`cyborg.bus.msgs` and publishers, subscriptions, services and
actions made from them are generic in them, so a typo in a field name is a type error at every
boundary: building a message, reading one in a callback, a service's response, an action's
result. With a type *name* instead of a class the same code is typed ``Any`` and passes, which
is what this shows too.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from mypy import api

ROOT = Path(__file__).resolve().parents[2]

SNIPPET = '''\
from cyborg.bus import Node
from cyborg.bus.msgs.cyborg_msgs.action import MoveToGoal
from cyborg.bus.msgs.geometry_msgs.msg import Pose2D
from cyborg.bus.msgs.std_msgs.msg import String
from cyborg.bus.msgs.std_srvs.srv import SetBool
from cyborg.interfaces import robot


def typed(node: Node) -> None:
    chatter = node.create_publisher("chatter", String)
    chatter.publish(String(dat="hello"))  # building
    chatter.publish(SetBool.Request(data=True))  # publishing
    node.create_subscription("chatter", String, lambda message: message.dta)  # receiving
    client = node.create_client("enable", SetBool)
    print(client.call(SetBool.Request(data=True)).sucess)  # service
    action = node.create_action_client("move", MoveToGoal)
    goal = action.send_goal(MoveToGoal.Goal(goal_name="x", pose=Pose2D(x=0.0, y=0.0, theta=0.0),
                                            use_heading=False))
    print(goal.result()[1].outcom)  # action
    robot.POSE.publisher(node).publish(String(data="x"))  # contract publishing
    robot.POSE.subscription(node, lambda message: message.thta)  # contract receiving
    print(robot.DOCK.client(node).call(robot.DOCK.service_type.Request()).mesage)  # contract call


def fine(node: Node) -> None:
    chatter = node.create_publisher("chatter", String)
    chatter.publish(String(data="hello"))
    node.create_subscription("chatter", String, lambda message: print(message.data))
    print(node.create_client("enable", SetBool).call(SetBool.Request(data=True)).success)
    robot.POSE.publisher(node).publish(Pose2D(x=1.0, y=2.0, theta=0.0))
    robot.POSE.subscription(node, lambda message: print(message.theta))
    print(robot.DOCK.client(node).call(robot.DOCK.service_type.Request()).message)


def by_name(node: Node) -> None:  # type names give Any: nothing is checked here
    node.create_publisher("chatter", "std_msgs/msg/String").publish(SetBool.Request(data=True))
    node.create_subscription("chatter", "std_msgs/msg/String", lambda message: message.dta)
'''

EXPECTED = {
    "# building": 'Unexpected keyword argument "dat" for "std_msgs__msg__String"; '
                  'did you mean "data"?',
    "# publishing": 'Argument 1 to "publish" of "Publisher" has incompatible type '
                    '"std_srvs__srv__SetBool_Request"; expected "std_msgs__msg__String"',
    "# receiving": '"std_msgs__msg__String" has no attribute "dta"; maybe "data"?',
    "# service": '"std_srvs__srv__SetBool_Response" has no attribute "sucess"; '
                 'maybe "success"?',
    "# action": '"cyborg_msgs__action__MoveToGoal_Result" has no attribute "outcom"; '
                'maybe "outcome"?',
    "# contract publishing": 'Argument 1 to "publish" of "Publisher" has incompatible type '
                             '"std_msgs__msg__String"; expected "geometry_msgs__msg__Pose2D"',
    "# contract receiving": '"geometry_msgs__msg__Pose2D" has no attribute "thta"; '
                            'maybe "theta"?',
    "# contract call": '"std_srvs__srv__Trigger_Response" has no attribute "mesage"; '
                       'maybe "message"?',
}
"""The error strict mypy reports on each marked line of the snippet, and no other: a typo at
each boundary and the wrong message class for a publisher, also through a contract's
descriptor (:mod:`cyborg.interfaces`); none in ``fine`` (no false alarm)
nor in ``by_name`` (typed Any)."""


@pytest.mark.heavy
def test_strict_mypy_catches_misspelt_fields_at_the_bus_boundaries(tmp_path: Path) -> None:
    snippet = tmp_path / "typed_snippet.py"
    snippet.write_text(SNIPPET, encoding="utf-8")
    out, err, _status = api.run([str(snippet), "--strict", "--config-file",
                                 str(ROOT / "pyproject.toml"), "--no-error-summary",
                                 "--hide-error-context", "--no-pretty"])
    found = set()
    for line in out.splitlines():
        match = re.match(r".*typed_snippet\.py:(\d+): error: (.*?)(?:  \[[a-z-]+\])?$", line)
        if match:
            found.add((int(match[1]), match[2]))
    lines = SNIPPET.splitlines()
    expected = {(next(n for n, text in enumerate(lines, 1) if text.endswith(marker)), error)
                for marker, error in EXPECTED.items()}
    assert found == expected, out + err
