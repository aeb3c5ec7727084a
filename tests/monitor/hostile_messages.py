"""A hostile robot for the monitor's tests: random, malformed messages of every kind the
monitor's map reads (pose, scan, path, path state, battery, current goal, footprint,
``/tf_static``, map geometry, the detector's detections and predictions, the tracker's
objects), drawn from a
``random.Random`` (hypothesis's ``st.randoms()`` in the fuzz test, so failures shrink; a seeded
one in the browser test), published by a :class:`~tests.monitor.robot_messages.FakeMapRobot`.

Values come from :data:`NUMBERS`: NaN, the infinities, huge and tiny numbers, and ordinary ones;
lengths from lists that straddle the monitor's limits (8,192 beams, 3 to 256 corners, 200
objects); texts with quotes, markup, line breaks and 500 characters. And a tree runner's
``services`` message gone wrong (:func:`hostile_service_states`)."""

from __future__ import annotations

import math
import random
from typing import Any

import numpy as np

from cyborg.bus import Publisher
from cyborg.bus.msgs.builtin_interfaces.msg import Time
from cyborg.bus.msgs.cyborg_msgs.msg import ServiceState, ServiceStates
from cyborg.bus.msgs.diagnostic_msgs.msg import KeyValue
from cyborg.bus.msgs.std_msgs.msg import String
from tests.monitor.robot_messages import (
    FakeMapRobot,
    battery,
    detections,
    footprint,
    goal,
    map_geometry,
    map_object,
    path,
    pose,
    predictions,
    scan,
    tracked,
    tracked_objects,
    transforms,
)

NUMBERS = (math.nan, math.inf, -math.inf, 1e300, -1e300, 1e12, -1e12, 1e4 + 1, 5e-324, 0.0,
           -0.0)
"""Hostile float64 values; ordinary ones are drawn besides."""
NUMBERS32 = (math.nan, math.inf, -math.inf, 1e30, -1e30, 1e12, 1e4 + 1, 0.0)
"""Hostile values that a float32 holds (as they are, or as an infinity)."""
TEXTS = ("", "room1", "x" * 500, "a\nb", "ünïcødé ☃", "'\"<script>alert(1)</script>", "\t \r")
FRAMES = ("base_link", "laser", "camera_left", "", "x" * 300, "laser")
KINDS = ("pose", "scan", "path", "state", "battery", "goal", "footprint", "tf", "map",
         "detections", "predictions", "objects")


def number(rng: random.Random, hostile: tuple[float, ...] = NUMBERS) -> float:
    """A hostile value half the time, else an ordinary one (-50 to 50)."""
    return rng.choice(hostile) if rng.random() < 0.5 else rng.uniform(-50.0, 50.0)


def _text(rng: random.Random) -> str:
    return rng.choice(TEXTS)


def hostile_message(rng: random.Random, kind: str) -> Any:
    """One message of ``kind`` (one of :data:`KINDS`), its values and lengths drawn by ``rng``."""
    def n32() -> float:
        return number(rng, NUMBERS32)

    if kind == "pose":
        return pose(number(rng), number(rng), number(rng))
    if kind == "scan":
        beams = rng.choice((0, 1, 100, 540, 541, 542, 8192, 8193, 20000))
        return scan(np.full(beams, n32(), np.float32), beams=beams,
                    angle_min=rng.choice((-2.356, n32())),
                    increment=rng.choice((0.00873, 0.0, n32())),
                    angle_max=rng.choice((None, n32())), range_min=n32(),
                    range_max=rng.choice((30.0, n32())))
    if kind == "path":
        return path([(number(rng), number(rng)) for _ in range(rng.choice((0, 1, 5, 30)))])
    if kind == "state":
        return String(data=_text(rng))
    if kind == "battery":
        return battery(n32(), _text(rng))
    if kind == "goal":
        return goal(_text(rng), number(rng), number(rng), number(rng),
                    heading=rng.random() < 0.5)
    if kind == "footprint":
        return footprint([(n32(), n32()) for _ in range(rng.choice((0, 2, 3, 12, 256, 257,
                                                                     1000)))])
    if kind == "tf":
        return transforms(*[(rng.choice(FRAMES), rng.choice(FRAMES), number(rng), number(rng),
                             number(rng)) for _ in range(rng.randint(1, 3))])
    if kind == "map":
        return map_geometry(
            lines=np.array([n32() for _ in range(rng.choice((0, 3, 4, 8)))], np.float32),
            points=np.array([n32() for _ in range(rng.choice((0, 1, 2, 6)))], np.float32),
            objects=[map_object(_text(rng), rng.randint(0, 9), _text(rng),
                                (number(rng), number(rng), number(rng)),
                                [n32() for _ in range(rng.choice((0, 3, 4, 8)))])],
            source=_text(rng))
    if kind == "objects":
        return tracked_objects(*[
            tracked(rng.choice((0, 1, 2, 2**32 - 1)), _text(rng), (number(rng), number(rng)),
                    (n32(), n32()), confidence=n32(), last_seen=rng.choice((0.0, 5.0, 1e9)),
                    times_seen=rng.choice((0, 1, 2**32 - 1)))
            for _ in range(rng.choice((0, 1, 3, 250)))],
            now=rng.choice((0.0, 10.0, 2e9)), frame=rng.choice(("map", "map", "odom", "")))
    objects = [(_text(rng), number(rng), number(rng))
               for _ in range(rng.choice((0, 1, 3, 250)))]
    return detections(*objects) if kind == "detections" else predictions(*objects)


def publish(robot: FakeMapRobot, kind: str, message: Any) -> None:
    """Publishes ``message`` on ``robot``'s topic for ``kind``."""
    publishers: dict[str, Publisher[Any]] = {
        "pose": robot.pose, "scan": robot.scan, "path": robot.path, "state": robot.path_state,
        "battery": robot.battery, "goal": robot.goal, "footprint": robot.footprint,
        "tf": robot.tf_static, "map": robot.map, "detections": robot.detections,
        "predictions": robot.predictions, "objects": robot.objects}
    publishers[kind].publish(message)


def certainly_bad() -> list[tuple[str, Any]]:
    """One message of each kind that the monitor must warn about, with the warning's kind."""
    return [
        ("pose", pose(math.nan, 1.0, 0.0)),
        ("scan", scan(np.full(8193, 1.0, np.float32), beams=8193)),
        ("path", path([(math.inf, 0.0), (1.0, 1.0)])),
        ("battery", battery(math.nan)),
        ("goal", goal("room1", math.nan, 0.0)),
        ("footprint", footprint([(0.1, 0.1)])),
        ("tf", transforms(("base_link", "laser", math.nan, 0.0, 0.0))),
        ("map", map_geometry(points=np.array([1.0, math.nan], np.float32))),
        ("detections", detections(("person", 0.9, math.inf))),
        ("objects", tracked_objects(tracked(1, at=(math.nan, 0.0)))),
    ]


def hostile_service_states(rng: random.Random, composites: list[str]) -> ServiceStates:
    """A tree runner's ``services`` message gone wrong: composites the tree has and has not,
    names, keys, values and errors from :data:`TEXTS` and 2,000 characters long, nanosecond
    counts past a second, runs from 0 to the most a uint32 holds, up to 2,000 services (and
    up to 200 written keys each of a few)."""
    def text() -> str:
        return "k" * 2_000 if rng.random() < 0.1 else _text(rng)

    def stamp() -> Time:
        return Time(sec=rng.choice((0, 1, -1, 2**31 - 1, -(2**31))),
                    nanosec=rng.choice((0, 5, 999_999_999, 1_000_000_000, 2**32 - 1)))

    ids = [*composites, "", "nope", "x" * 500]
    count = rng.choice((0, 1, 4, 2000))
    keys = (0, 1, 3, 200) if count < 10 else (0, 1)
    return ServiceStates(stamp=stamp(), tree_id=text(), services=[
        ServiceState(composite=rng.choice(ids), service=text(), active=rng.random() < 0.5,
                     runs=rng.choice((0, 1, 7, 2**32 - 1)), last_run=stamp(),
                     wrote=[KeyValue(key=text(), value=text())
                            for _ in range(rng.choice(keys))],
                     error=text())
        for _ in range(count)])
