"""Hostile input end to end: random, malformed robot messages of every kind (absurd maps,
NaN and infinite poses, scans of the wrong length, giant footprints, bad transforms, bad
current goals, bad detections and tracked objects; tests/monitor/hostile_messages.py) go over
the bus into a running monitor, whose page-bound messages must stay strict JSON within the
documented limits (docs/monitor.md, "The map's data path"); each kind that cannot be drawn is a
warning; no exception is logged and the page's connection stays open."""

from __future__ import annotations

import logging
import math
import random
import re
from functools import partial
from typing import Any

import anyio
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cyborg.interfaces import detector, perception
from tests.monitor.hostile_messages import KINDS, certainly_bad, hostile_message, publish
from tests.monitor.monitor_protocol import RECEIVE_TIMEOUT, local_client
from tests.monitor.robot_messages import map_geometry, pose
from tests.monitor.test_robot_protocol import _followed, _map_on, _subscribed, robot_bus
from tests.running_system import wait_until
from tests.strict_json import strict_loads

WORLD_M = 10_000.0
"""Farthest a pose, goal or path point may be from the origin (m)."""
KEY = re.compile(r"^[0-9a-f]{32}$")


def _next(socket: Any, timeout: float = RECEIVE_TIMEOUT) -> dict[str, Any]:
    """The monitor's next message, read as strict JSON (NaN and Infinity refused)."""
    async def receive() -> Any:
        with anyio.fail_after(timeout):
            return await socket._send_rx.receive()

    message = socket.portal.call(receive)
    assert message["type"] == "websocket.send", f"the connection ended: {message}"
    decoded: dict[str, Any] = strict_loads(message["text"])
    return decoded


def _finite(values: Any, limit: float) -> bool:
    return all(isinstance(v, int | float) and math.isfinite(v) and abs(v) <= limit
               for v in values)


def _check_rs(message: dict[str, Any]) -> None:
    x, y, theta = message["p"]
    assert _finite((x, y), WORLD_M) and -math.pi <= theta <= math.pi, message["p"]
    scan = message.get("sc")
    if scan is not None:
        assert len(scan["r"]) <= 8192 and 0 < scan["mx"] <= WORLD_M * 1000
        assert _finite((scan["a0"], scan["da"]), math.tau) and scan["da"] != 0
        assert all(isinstance(r, int) and -1 <= r <= scan["mx"] for r in scan["r"])
        assert "m" not in scan or _finite(scan["m"], 16 * 100.0)
    footprint = message.get("fp")
    if footprint is not None:
        assert 6 <= len(footprint) <= 512 and len(footprint) % 2 == 0
        assert _finite(footprint, 100.0)
    goal = message.get("goal")
    if goal is not None:
        assert 0 < len(goal["name"]) <= 200 and isinstance(goal["h"], bool)
        assert _finite(goal["p"][:2], WORLD_M) and abs(goal["p"][2]) <= math.pi
    battery = message.get("bat")
    if battery is not None:
        assert 0 <= battery["pct"] <= 100 and len(battery["dock"]) <= 200
    assert len(message.get("st", "")) <= 200 and len(message.get("node", "")) <= 10_000


def check(message: dict[str, Any]) -> None:
    """``message`` is what docs/monitor.md promises a page, whatever the robot sent."""
    kind = message["t"]
    if kind == "rs":
        _check_rs(message)
    elif kind == "path":
        xy = message["xy"]
        assert len(xy) % 2 == 0 and len(xy) <= 2 * 20_000
        assert all(isinstance(v, int) and abs(v) <= WORLD_M * 1000 for v in xy)
    elif kind == "det":
        assert len(message["d"]) <= 200
        for item in message["d"]:
            assert _finite(item["p"], WORLD_M + 200) and 0 <= item["score"] <= 1
            assert len(item["label"]) <= 60
    elif kind == "obj":
        assert len(message["o"]) <= 200 and len({item["id"] for item in message["o"]}) == len(
            message["o"])
        for item in message["o"]:
            assert _finite((item["x"], item["y"]), WORLD_M)
            assert _finite((item["vx"], item["vy"]), 20.0) and 0 <= item["conf"] <= 1
            assert 0 <= item["age"] <= 3600 and len(item["label"]) <= 60
    elif kind == "map_ref":
        assert message["key"] is None or KEY.match(message["key"])
        counts = message["counts"]
        assert counts is None or (counts["points"] <= 2_000_000 and counts["lines"] <= 200_000
                                  and counts["objects"] <= 10_000)
    elif kind == "robot_warn":
        text = message["message"]
        assert 0 < len(text) < 1000 and "\n" not in text
        assert text.startswith(message["kind"]) and message["count"] >= 1


def _settle(socket: Any, fake: Any, marker: float, warned: set[str]) -> None:
    """Publishes a good pose at x = ``marker`` after what came before it, and checks every
    message up to the ``rs`` that carries it (by then the monitor has read the rest)."""
    fake.pose.publish(pose(marker, 0.0, 0.0))
    for _ in range(2000):
        message = _next(socket)
        check(message)
        if message["t"] == "robot_warn":
            warned.add(message["kind"])
        if message["t"] == "rs" and message["p"][0] == marker:
            return
    raise AssertionError(f"no rs with the pose at x = {marker}")


def _drain(socket: Any, request: int, warned: set[str]) -> set[str]:
    """Checks every message up to the answer to a ping numbered ``request``; the kinds warned
    of so far (``warned``, with those that came now)."""
    socket.send_json({"t": "ping", "req": request})
    while (message := _next(socket))["t"] != "pong":
        check(message)
        if message["t"] == "robot_warn":
            warned.add(message["kind"])
    assert message["req"] == request
    return warned


@pytest.mark.heavy
def test_hostile_messages_of_every_kind_never_break_the_page_bound_stream(
        caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.WARNING)
    with robot_bus() as (monitor, fake), local_client(monitor.app) as client, \
            client.websocket_connect("/ws") as socket:
        _map_on(socket)
        _followed(monitor, fake)
        graph = monitor.node.context.graph
        wait_until(partial(_subscribed, graph,
                           detector.DETECTIONS.full_name("/robot1/detector")), 10.0)
        wait_until(partial(_subscribed, graph, perception.OBJECTS.full_name("/robot1")), 10.0)
        warned: set[str] = set()
        fake.map.publish(map_geometry(points=np.zeros(2 * 2_000_001, np.float32)))
        wait_until(lambda: "map" in _drain(socket, 1, warned), 30.0,
                   "a warning about a map of 2,000,001 points")
        rounds = iter(range(2, 1_000_000))

        @settings(max_examples=40, deadline=None, derandomize=True,
                  suppress_health_check=[HealthCheck.too_slow])
        @given(rng=st.randoms(use_true_random=False), count=st.integers(1, 12))
        def hostile_burst(rng: random.Random, count: int) -> None:
            for _ in range(count):
                kind = rng.choice(KINDS)
                publish(fake, kind, hostile_message(rng, kind))
            _settle(socket, fake, next(rounds) / 1000, warned)

        hostile_burst()
        for kind, message in certainly_bad():
            publish(fake, kind, message)
        expected = {kind for kind, _message in certainly_bad()}
        wait_until(lambda: expected <= _drain(socket, next(rounds), warned), 30.0,
                   f"warnings of every kind ({sorted(expected)})")
        fake.pose.publish(pose(3.0, 4.0, 0.0))
        for _ in range(400):  # the robot is still followed, the connection still open
            message = _next(socket)
            check(message)
            if message["t"] == "rs" and message["p"] == [3.0, 4.0, 0.0]:
                break
        else:
            raise AssertionError("the good pose after the storm never came")
    errors = [record for record in caplog.records if record.levelno >= logging.ERROR]
    assert errors == [], [record.getMessage() for record in errors]

