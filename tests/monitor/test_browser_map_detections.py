"""The detected objects on the map, in headless Chromium against the stand-in monitor
(tests/monitor/map_page.py): each ``det`` object drawn where the monitor placed it, as a diamond
in the robot's colour with its class; the layer switches them off; a malformed ``det`` is a
warning; objects older than 3 s are no longer drawn."""

from __future__ import annotations

import json

import pytest
from playwright.sync_api import Browser

from tests.monitor.map_page import ROBOT, START, StandInMonitor, on_map, open_map_page, pixel

pytestmark = pytest.mark.heavy


def test_detected_objects_are_drawn_where_the_monitor_placed_them(
        browser: Browser, server: StandInMonitor) -> None:
    errors: list[str] = []
    page = open_map_page(browser, server.url, errors)
    page.wait_for_function(f"window.__map.robot({ROBOT!r}) !== null")
    person = (START[0] + 1.5, START[1] + 2.0)
    server.push({"t": "det", "ns": ROBOT, "id": 1, "d": [
        {"label": "person", "score": 0.93, "p": list(person)},
        {"label": "chair", "score": 0.5, "p": [START[0] - 2.0, START[1]]}]})
    page.wait_for_function("window.__map.moving.detections === 2")
    seen = on_map(page, f"m.robot({ROBOT!r}).seen")
    assert seen[0] == {"label": "person", "score": 0.93, "x": person[0], "y": person[1]}
    colour = on_map(page, f"m.colourOf({ROBOT!r})")
    sx, sy = on_map(page, f"m.toScreen({person[0]}, {person[1]})")
    assert pixel(page, sx, sy) == [255, 255, 255, 255], "the diamond's white middle"
    edge = pixel(page, sx, sy - 6)
    wanted = [int(colour[i:i + 2], 16) for i in (1, 3, 5)]
    assert all(abs(a - b) <= 60 for a, b in zip(edge[:3], wanted, strict=True)), \
        f"outlined in the robot's colour {colour}, not {edge}"
    page.click("#map-layers summary")
    page.uncheck("#map-layer-list input[data-layer=detections]")
    page.wait_for_function("window.__map.moving.detections === 0")
    page.check("#map-layer-list input[data-layer=detections]")
    page.wait_for_function("window.__map.moving.detections === 2")
    server.push({"t": "det", "ns": ROBOT, "id": 2, "d": [{"label": "x", "p": ["far", 0]}]},
                {"t": "det", "ns": ROBOT, "id": 3, "d": "many"})
    page.wait_for_function("window.__map.warnings.some(w => w.kind === 'bad det' && "
                           "w.count === 2)")
    assert on_map(page, "m.moving.detections") == 2, "a bad message changes nothing"
    page.wait_for_function("window.__map.moving.detections === 0", timeout=10000)
    assert errors == [], json.dumps(errors)
