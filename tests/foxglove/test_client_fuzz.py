"""Whatever a client sends, the Foxglove server stays up: subscriptions and unsubscriptions with
random ids, protocol messages with fields of the wrong kind, garbage text and binary frames and
bytes that are no WebSocket frame at all. A well-behaved client is served afterwards, and the bus
is left once the fuzzing clients are gone."""

from __future__ import annotations

import contextlib
import json
from typing import Any

from hypothesis import given, settings
from hypothesis import strategies as st

from cyborg.bus.msgs.geometry_msgs.msg import Pose2D
from cyborg.bus.msgs.std_msgs.msg import String
from tests.foxglove.conftest import Repeating, Served, wait_for

ids = st.one_of(st.integers(0, 12), st.integers(-2**63, 2**64), st.none(), st.text(max_size=5),
                st.floats(allow_nan=True), st.lists(st.integers(0, 5), max_size=2))
"""Channel and subscription ids: mostly ones that exist, some of every wrong kind."""
json_values = st.recursive(st.none() | st.booleans() | st.integers() | st.text(max_size=10),
                           lambda inner: st.lists(inner, max_size=3)
                           | st.dictionaries(st.text(max_size=8), inner, max_size=3),
                           max_leaves=8)
OPS = ["subscribe", "unsubscribe", "advertise", "unadvertise", "getParameters",
       "setParameters", "subscribeParameterUpdates", "subscribeConnectionGraph",
       "fetchAsset", "playbackControl", "nothing"]
messages = st.one_of(
    st.builds(lambda pairs: {"op": "subscribe", "subscriptions": [
        {"id": sub, "channelId": channel} for sub, channel in pairs]},
        st.lists(st.tuples(ids, ids), max_size=4)),
    st.builds(lambda subs: {"op": "unsubscribe", "subscriptionIds": subs},
              st.lists(ids, max_size=4)),
    st.builds(lambda op, fields: {**fields, "op": op}, st.sampled_from(OPS),
              st.dictionaries(st.sampled_from(["channels", "subscriptions", "id", "channelId",
                                               "subscriptionIds", "names", "uri", "requestId"]),
                              json_values, max_size=3)),
)
actions = st.one_of(
    st.builds(lambda message: ("text", json.dumps(message)), messages),
    st.builds(lambda garbage: ("text", garbage), st.text(max_size=60)),
    st.builds(lambda garbage: ("binary", garbage), st.binary(max_size=60)),
)


def act(served: Served, steps: list[tuple[str, Any]], raw: bytes) -> None:
    """One fuzzing client: its steps as frames, then ``raw`` bytes on the socket, if any."""
    with served.client() as client, contextlib.suppress(Exception):
        client.connection.close_timeout = 0.2  # garbage may leave no close handshake to wait for
        for kind, payload in steps:
            client.connection.send(payload if kind == "text" else bytes(payload))
            client.read(0.001)
        if raw:
            client.connection.socket.sendall(raw)
        client.read(0.02)


def test_the_server_survives_anything_a_client_sends_and_serves_the_next(
        served: Served) -> None:
    pose = served.publisher_node.create_publisher("pose", Pose2D)
    served.publisher_node.create_publisher("note", String)
    stream = Repeating(pose, lambda count: Pose2D(x=float(count), y=0.0, theta=0.0))
    try:
        with served.client() as first:
            first.channel("/cyborg/pose")
            first.channel("/cyborg/note")

        @settings(max_examples=80, deadline=None, derandomize=True)
        @given(steps=st.lists(actions, max_size=8), raw=st.one_of(st.just(b""),
                                                                 st.binary(max_size=40)))
        def fuzz(steps: list[tuple[str, Any]], raw: bytes) -> None:
            act(served, steps, raw)

        fuzz()
        with served.client() as client:
            subscription = client.subscribe("/cyborg/pose")
            decoded = served.context.types.deserialize(client.payloads(subscription)[0],
                                                       "geometry_msgs/msg/Pose2D")
            assert decoded in stream.sent
            assert served.server.relays.watched("/cyborg/pose") == 1
        assert wait_for(lambda: served.subscriptions("/cyborg/pose") == 0)
        assert served.server.relays.watched("/cyborg/pose") == 0
    finally:
        stream.stop()
