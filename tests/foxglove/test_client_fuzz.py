"""Whatever a client sends, the Foxglove server stays up: subscriptions and unsubscriptions with
random ids, floods of subscriptions to channels that do not exist, protocol messages with fields
of the wrong kind, garbage text and binary frames and bytes that are no WebSocket frame at all.
A well-behaved client is served afterwards, the SDK's lines about the clients stay few (one per
client and kind, then a count), and nothing of the fuzzing clients is kept once they are gone."""

from __future__ import annotations

import contextlib
import gc
import json
import logging
from typing import Any

from hypothesis import given, settings
from hypothesis import strategies as st

from cyborg.bus.msgs.geometry_msgs.msg import Pose2D
from cyborg.bus.msgs.std_msgs.msg import String
from cyborg.foxglove.resubscribe import Resubscriber
from cyborg.foxglove.sdk_log import KINDS, LIMITER, SDK_CLIENT_LOGGER, TRACKED
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
    st.builds(lambda start, count: ("flood", (start, count)),
              st.integers(10_000, 2**32 - 1000), st.integers(20, 120)),
    st.builds(lambda garbage: ("text", garbage), st.text(max_size=60)),
    st.builds(lambda garbage: ("binary", garbage), st.binary(max_size=60)),
)


def act(served: Served, steps: list[tuple[str, Any]], raw: bytes) -> None:
    """One fuzzing client: its steps as frames, then ``raw`` bytes on the socket, if any."""
    with served.client() as client, contextlib.suppress(Exception):
        client.connection.close_timeout = 0.2  # garbage may leave no close handshake to wait for
        for kind, payload in steps:
            if kind == "flood":  # subscriptions to channels that do not exist, one per frame
                start, count = payload
                for number in range(count):
                    client.connection.send(json.dumps({"op": "subscribe", "subscriptions": [
                        {"id": number, "channelId": start + number}]}))
            else:
                client.connection.send(payload if kind == "text" else bytes(payload))
            client.read(0.001)
        if raw:
            client.connection.socket.sendall(raw)
        client.read(0.02)


class Lines(logging.Handler):
    """Counts the lines that reach the handlers of the SDK's client logger."""

    def __init__(self) -> None:
        super().__init__()
        self.count = 0

    def emit(self, record: logging.LogRecord) -> None:
        self.count += 1


def test_the_server_survives_anything_a_client_sends_and_serves_the_next(
        served: Served) -> None:
    lines = Lines()
    logging.getLogger(SDK_CLIENT_LOGGER).addHandler(lines)
    clients, suppressed = 0, LIMITER.suppressed
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
            nonlocal clients
            clients += 1
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
        assert wait_for(lambda: served.server.relays.subscriptions() == 0)

        def resubscribers() -> int:
            gc.collect()
            return sum(isinstance(thing, Resubscriber) for thing in gc.get_objects())
        assert wait_for(lambda: resubscribers() == 0)
        assert LIMITER.tracked_now() <= TRACKED + len(KINDS)
        assert LIMITER.suppressed > suppressed  # the floods were counted, not written
        # per client and kind: its first line and a count, and again for lines the SDK wrote
        # after the client had gone
        assert lines.count <= 4 * len(KINDS) * (clients + 2)
    finally:
        stream.stop()
        logging.getLogger(SDK_CLIENT_LOGGER).removeHandler(lines)
