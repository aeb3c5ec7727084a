"""The tracked objects on the map, in headless Chromium against a real monitor on an isolated
bus: a fake robot under /cyborg on a small map and a fake tracker publishing its
``/cyborg/objects`` a few times a second, as the tracker does. Each object is drawn where the
tracker put it, in the robot's colour family (a person round, anything else square), with its
label and id; a moving one gets an arrow along its velocity, an old one is faded; hovering a
marker tells what the tracker knows; the raw "Detected objects" layer goes off by default;
an object left out of the list disappears; the layer switches them off. Against the stand-in
monitor: a "Detected objects" layer the user chose stays as chosen, and a malformed ``obj`` is
a warning that changes nothing."""

from __future__ import annotations

import json
import threading
from collections.abc import Iterator
from contextlib import contextmanager

import pytest
from playwright.sync_api import Browser, Page

from cyborg.bus import BusConfig, Context, Node, Publisher
from cyborg.bus.msgs.cyborg_msgs.msg import TrackedObject, TrackedObjects
from cyborg.interfaces import perception
from cyborg.monitor import Monitor
from tests.monitor.map_page import ROBOT as STAND_IN_ROBOT
from tests.monitor.map_page import START, StandInMonitor, on_map, open_map_page, pixel, rgb
from tests.monitor.robot_messages import FakeMapRobot, map_geometry, pose, tracked, tracked_objects
from tests.running_system import wait_until

pytestmark = pytest.mark.heavy

ROBOT = "/cyborg"
STILL = tracked(1, "person", (3.0, 2.0), confidence=0.8, last_seen=10.0, times_seen=7)
WALKING = tracked(2, "person", (6.0, 1.5), (0.0, 1.0), confidence=0.9, last_seen=10.0)
CHAIR = tracked(3, "chair", (2.0, 4.0), confidence=0.6, last_seen=10.0)
OLD = tracked(4, "person", (8.0, 3.5), confidence=0.3, last_seen=6.0)
"""Last seen 4 s before the list's stamp."""


class FakeTracker:
    """Publishes ``objects`` (the list of the moment) ten times a second, as a tracker would."""

    def __init__(self, publisher: Publisher[TrackedObjects]) -> None:
        self.publisher = publisher
        self.objects: list[TrackedObject] = []
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)

    def _run(self) -> None:
        while not self._stop.wait(0.1):
            self.publisher.publish(tracked_objects(*self.objects, now=10.0))

    @contextmanager
    def running(self) -> Iterator[FakeTracker]:
        self._thread.start()
        try:
            yield self
        finally:
            self._stop.set()
            self._thread.join(5)


def _centre(page: Page, item: TrackedObject) -> tuple[float, float]:
    sx, sy = on_map(page, f"m.toScreen({item.position.x}, {item.position.y})")
    return float(sx), float(sy)


def _near(found: list[int], wanted: list[int], slack: int = 40) -> bool:
    return all(abs(a - b) <= slack for a, b in zip(found, wanted, strict=True))


def test_tracked_objects_are_drawn_where_the_tracker_put_them(browser: Browser) -> None:
    with Context(BusConfig.isolated()) as context:
        monitor = Monitor(Node("monitor", "/monitor", context=context), port=0)
        robot = FakeMapRobot(Node("arnl", ROBOT, context=context), ROBOT)
        tracker = FakeTracker(perception.OBJECTS.publisher(Node("tracker", ROBOT,
                                                                context=context), ROBOT))
        monitor.start()
        try:
            robot.map.publish(map_geometry())
            errors: list[str] = []
            page = open_map_page(browser, f"http://127.0.0.1:{monitor.port}/", errors)

            def placed() -> bool:  # poses are not latched: again until one is followed
                robot.pose.publish(pose(1.0, 1.0, 0.0))
                return bool(on_map(page, f"m.robot({ROBOT!r})?.pose"))

            wait_until(placed, 30.0, "the robot on the page")
            with tracker.running():
                tracker.objects = [STILL, WALKING, CHAIR, OLD]
                page.wait_for_function("window.__map.moving.tracked === 4", timeout=20000)
                _check_drawing(page)
                _check_tooltip(page)
                tracker.objects = [STILL, WALKING, OLD]
                page.wait_for_function("window.__map.moving.tracked === 3", timeout=10000)
                sx, sy = _centre(page, CHAIR)
                assert pixel(page, sx, sy)[3] == 0, "the chair left the list: gone"
                page.click("#map-layers summary")
                page.uncheck("#map-layer-list input[data-layer=tracked]")
                page.wait_for_function("window.__map.moving.tracked === 0")
                page.check("#map-layer-list input[data-layer=tracked]")
                page.wait_for_function("window.__map.moving.tracked === 3")
            page.wait_for_function("window.__map.moving.tracked === 0", timeout=10000)
            assert errors == [], json.dumps(errors)
        finally:
            monitor.stop()


def _check_drawing(page: Page) -> None:
    known = {item["id"]: item for item in on_map(page, f"m.robot({ROBOT!r}).tracked")}
    assert (known[1]["x"], known[1]["y"], known[1]["label"]) == (3.0, 2.0, "person")
    assert (known[2]["vx"], known[2]["vy"]) == (0.0, 1.0)
    assert known[1]["alpha"] > 0.9 and known[4]["alpha"] < 0.55, \
        "an object last seen 4 s ago is faded"
    assert on_map(page, "m.moving.arrows") == 1, "only the walking person has an arrow"
    assert on_map(page, "m.moving.trackedLabels") == 4, "a small map zoomed in: every label"
    colour = rgb(on_map(page, f"m.colourOf({ROBOT!r})"))
    tint = [round((c + 255) / 2) for c in colour]
    sx, sy = _centre(page, STILL)
    assert _near(pixel(page, sx, sy), [*tint, 255]), "a marker filled with the robot's tint"
    assert _near(pixel(page, sx + 7, sy)[:3], colour, 60), "outlined in the robot's colour"
    assert pixel(page, sx + 7, sy - 7)[3] == 0, "a person is round: its box's corner is empty"
    sx, sy = _centre(page, CHAIR)
    assert _near(pixel(page, sx + 6, sy - 6)[:3], colour, 60), "anything else is square"
    sx, sy = _centre(page, WALKING)
    scale = on_map(page, "m.view().scale")
    assert _near(pixel(page, sx, sy - 11)[:3], colour, 60), "the arrow points up: north"
    assert pixel(page, sx, sy + 11)[3] == 0, "and only that way"
    assert pixel(page, sx, sy - max(scale, 17) - 3)[3] == 0, "about 1 s of motion long"
    sx, sy = _centre(page, OLD)
    assert pixel(page, sx, sy)[3] < 160, "faded: the map shows through"
    assert not page.is_checked("#map-layer-list input[data-layer=detections]"), \
        "the raw detections' layer went off once the tracker's objects came"


def _check_tooltip(page: Page) -> None:
    box = page.locator("#map-canvas").bounding_box()
    assert box is not None
    sx, sy = _centre(page, STILL)
    page.mouse.move(box["x"] + sx + 2, box["y"] + sy + 1)
    page.wait_for_function("window.__map.objectTip() !== null")
    text = on_map(page, "m.objectTip()")
    assert text.splitlines()[:3] == [f"person #1 · {ROBOT}", "confidence 80 %",
                                     "speed 0.00 m/s"], text
    assert text.splitlines()[3].startswith("last seen 0.") and text.endswith(", 7 times")
    assert page.is_visible("#map-object-tip")
    page.mouse.move(box["x"] + 5, box["y"] + 5)
    page.wait_for_function("window.__map.objectTip() === null")


def test_a_chosen_detections_layer_stays_and_a_malformed_list_changes_nothing(
        browser: Browser, server: StandInMonitor) -> None:
    errors: list[str] = []
    page = open_map_page(browser, server.url, errors)
    page.wait_for_function(f"window.__map.robot({STAND_IN_ROBOT!r}) !== null")
    page.click("#map-layers summary")
    page.uncheck("#map-layer-list input[data-layer=detections]")
    page.check("#map-layer-list input[data-layer=detections]")  # chosen: on
    x, y = START[0] + 1.0, START[1] + 1.0
    server.push({"t": "obj", "ns": STAND_IN_ROBOT, "id": 1, "stamp": 5.0, "o": [
        {"id": 3, "label": "person", "x": x, "y": y, "vx": 0, "vy": 0, "conf": 0.9, "age": 0,
         "seen": 2}]})
    page.wait_for_function("window.__map.moving.tracked === 1")
    assert page.is_checked("#map-layer-list input[data-layer=detections]"), \
        "a layer the user chose is left as chosen"
    server.push({"t": "obj", "ns": STAND_IN_ROBOT, "id": 2, "o": "many"},
                {"t": "obj", "ns": STAND_IN_ROBOT, "id": 3, "o": [{"id": 1, "x": "far", "y": 0}]})
    page.wait_for_function("window.__map.warnings.some(w => w.kind === 'bad obj' && "
                           "w.count === 2)")
    assert [item["id"] for item in on_map(page, f"m.robot({STAND_IN_ROBOT!r}).tracked")] == [3]
    page.reload()
    page.wait_for_function("window.__map && window.__map.firstPaint !== null", timeout=20000)
    page.click("#map-layers summary")
    assert page.is_checked("#map-layer-list input[data-layer=detections]"), "kept for next time"
    assert errors == [], json.dumps(errors)
