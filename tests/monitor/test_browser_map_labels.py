"""The map's labels in headless Chromium (Debian's, driven by Playwright), fed by a stand-in
monitor (tests/monitor/map_page.py): three robots on the campus map, one docked at the
charger and the others beside it on their way to the same goal, and a person the docked robot
tracks. Every robot's name, the person's and the dock's are drawn, the goal is named once, no
two label boxes overlap (the page's ``window.__map.labels()`` gives the boxes its last frame
drew) and none lies under the map's controls; the Labels layer hides them all; where there is
room for one label only, the robot's stays and the goal's gives way; long names are cut so
that a robot's label fits a phone. Screenshots:
map_labels_1400x900.png, map_labels_390x844.png."""

from __future__ import annotations

import itertools
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from playwright.sync_api import Browser, Page

from cyborg.monitor.map_store import map_key
from cyborg.nav.arnl_map import read_map
from tests.monitor.browser import screenshot
from tests.monitor.map_page import (
    StandInMonitor,
    control_boxes,
    map_ref,
    on_map,
    open_map_page,
    overlap,
    pack_map_blob,
    robot_state,
)

pytestmark = pytest.mark.heavy

CAMPUS_MAP = Path(__file__).resolve().parents[2] / "src/cyborg/app/data/campus.map"
CHARGER = (2.0, 1.2)
"""The campus map's dock, "Charger"."""
TO_OFFICE = {"st": "MOVING_TO_GOAL", "goal": {"name": "Office", "p": [11.0, 3.0, 0.0]}}
"""Two robots drive to the campus map's goal "Office"."""
ROBOTS: dict[str, tuple[float, float, float, dict[str, Any]]] = {
    "/cyborg": (*CHARGER, -1.571, {"bat": {"pct": 37, "charging": True, "dock": "DOCKED"},
                                   "node": "Charge"}),
    "/robot2": (2.6, 1.6, 0.0, {"bat": {"pct": 80, "charging": False, "dock": "UNDOCKED"},
                                "node": "MoveTo Office", **TO_OFFICE}),
    "/robot3": (2.3, 0.7, 3.1, {"bat": {"pct": 55, "charging": False, "dock": "UNDOCKED"},
                                "node": "MoveTo Office", **TO_OFFICE}),
}
PERSON = {"t": "obj", "ns": "/cyborg", "id": 1, "stamp": 0.0,
          "o": [{"id": 4, "label": "person", "x": 2.9, "y": 1.1, "vx": 0.0, "vy": 0.0,
                 "conf": 0.9, "age": 0.0, "seen": 12}]}


@pytest.fixture
def fleet() -> Iterator[StandInMonitor]:
    arnl_map = read_map(CAMPUS_MAP)
    blob = pack_map_blob(arnl_map)
    key = map_key(blob)
    messages: list[Any] = []
    for ns, (x, y, theta, extra) in ROBOTS.items():
        messages += [map_ref(ns, key, arnl_map), robot_state(ns, 1, x, y, theta, beams=11,
                                                              **extra)]
    with StandInMonitor({key: blob}, on_map=messages) as running:
        yield running


def _labels(page: Page, server: StandInMonitor) -> list[dict[str, Any]]:
    """The label boxes of a frame drawn after what the test did last, with the person tracked
    (the tracker's list is shown for 3 s after it comes: it is sent again)."""
    paints = on_map(page, "m.paints")
    server.push(PERSON)
    page.wait_for_function(f"window.__map.paints > {paints} && window.__map.moving.tracked === 1",
                           timeout=5000)
    found: list[dict[str, Any]] = on_map(page, "m.labels()")
    return found


@pytest.mark.parametrize(("width", "height"), [(1400, 900), (390, 844)])
def test_three_robots_at_the_charger_keep_every_label_clear_of_the_others(
        browser: Browser, fleet: StandInMonitor, width: int, height: int) -> None:
    errors: list[str] = []
    page = open_map_page(browser, fleet.url, errors, width, height)
    fleet.push({"t": "seat", "may_control": True, "control": True, "holder": "this page"})
    page.wait_for_function("window.__map.moving.names === 3 && "
                           "!document.getElementById('map-act').hidden", timeout=10000)
    page.click("#map-fit")
    labels = _labels(page, fleet)
    texts = [label["text"] for label in labels]
    assert sorted(label["text"].split(" ·")[0] for label in labels
                  if label["kind"] == "robot") == sorted(ROBOTS), texts
    assert "/cyborg · 37 % ⚡ · docked / Charge" in texts
    assert "Charger" in texts, "the dock's label gives way"
    assert texts.count("Office") == 1, "a goal two robots drive to is named once"
    if on_map(page, "m.view().scale") >= 8:  # tracked objects are labelled from 8 px a metre
        assert "person #4" in texts, "the person's label gives way"
    for a, b in itertools.combinations(labels, 2):
        assert not overlap([a["x0"], a["y0"], a["x1"], a["y1"]],
                           [b["x0"], b["y0"], b["x1"], b["y1"]]), (a, b)
    controls = [box for boxes in control_boxes(page).values() for box in boxes]
    for label in labels:
        box = [label["x0"], label["y0"], label["x1"], label["y1"]]
        assert not any(overlap(box, control) for control in controls), label
    screenshot(page, f"map_labels_{width}x{height}")
    # the Labels layer hides them all, and brings them back
    page.click("#map-layers > summary")
    page.uncheck("#map-layer-list input[data-layer=labels]")
    assert _labels(page, fleet) == []
    assert on_map(page, "m.moving.names") == 0
    page.check("#map-layer-list input[data-layer=labels]")
    assert len(_labels(page, fleet)) == len(labels)
    assert errors == []


def test_where_one_label_fits_the_robot_keeps_it_and_the_goal_gives_way(
        browser: Browser, fleet: StandInMonitor) -> None:
    errors: list[str] = []
    page = open_map_page(browser, fleet.url, errors)
    placed = page.evaluate("""async () => {
        const { LabelLayout } = await import('/static/js/map/labels.js');
        const ctx = document.createElement('canvas').getContext('2d');
        const line = (text) => [{text, font: '11px sans-serif', colour: '#000'}];
        // a canvas with room for one line of text beside the point, and no more
        const layout = new LabelLayout(140, 20);
        layout.add({kind: 'goal', at: [4, 10], gap: 4, lines: line('Office')});
        layout.add({kind: 'robot', at: [4, 10], gap: 4, lines: line('/cyborg · 37 %')});
        return layout.place(ctx).map((label) => label.lines[0].text);
    }""")
    assert placed == ["/cyborg · 37 %"]
    assert errors == []


def test_long_names_are_cut_so_that_a_robots_label_fits_a_phone(browser: Browser) -> None:
    arnl_map = read_map(CAMPUS_MAP)
    blob = pack_map_blob(arnl_map)
    key = map_key(blob)
    ns = "/" + "a_very_long_fleet_namespace_" * 3  # 85 characters
    node = "MoveTo " + "somewhere far away " * 5
    messages = [map_ref(ns, key, arnl_map),
                robot_state(ns, 1, *CHARGER, 0.0, beams=11, node=node,
                            bat={"pct": 37, "charging": True, "dock": "DOCKED"})]
    with StandInMonitor({key: blob}, on_map=messages) as server:
        errors: list[str] = []
        page = open_map_page(browser, server.url, errors, 390, 844)
        page.wait_for_function("window.__map.moving.names === 1", timeout=10000)
        [label] = [found for found in on_map(page, "m.labels()") if found["kind"] == "robot"]
        first, second = label["text"].split(" / ")
        assert first == f"{ns[:31]}… · 37 % ⚡ · docked"
        assert second == f"{node[:39]}…"
        assert 0 <= label["x0"] < label["x1"] <= on_map(page, "m.view().width")
        assert errors == []
