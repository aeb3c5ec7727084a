"""Fit keeps the map clear of its own controls, in headless Chromium (Debian's, driven by
Playwright) fed by a stand-in monitor (tests/monitor/map_page.py): on AMROffice, whose Dock,
room2 and room4 lie along its bottom edge, with the robot docked at the Dock and a page that
may act (so the actions' bar is shown), no goal, dock, home or robot marker lies under the
map's toolbar, the actions' bar or STOP after Fit, on a desktop (1400x900) and a phone
(390x844); the actions' bar coming later fits the map again; of the rectangles the controls
leave free, the one that shows the map largest is chosen. Screenshots:
map_fit_1400x900.png, map_fit_390x844.png."""

from __future__ import annotations

from collections.abc import Iterator

import pytest
from playwright.sync_api import Browser, Page

from cyborg.monitor.map_store import map_key
from cyborg.nav.arnl_map import ArnlMap, read_map
from tests.conftest import shared_dir
from tests.monitor import map_page
from tests.monitor.browser import screenshot
from tests.monitor.map_page import StandInMonitor
from tests.running_system import wait_until

pytestmark = pytest.mark.heavy

ROBOT = "/cyborg"
MARKER_PX = 6
"""A goal's dot, a dock's square: half their size with the outline."""
MARKED = {"goal", "goal_with_heading", "dock", "home"}


@pytest.fixture
def amr_office() -> Iterator[tuple[ArnlMap, StandInMonitor]]:
    arnl_map = read_map(shared_dir() / "maps" / "AMROffice.map")
    blob = map_page.pack_map_blob(arnl_map)
    key = map_key(blob)
    [dock] = [item for item in arnl_map.objects if item.kind == "Dock"]
    docked = map_page.robot_state(ROBOT, 1, dock.x, dock.y, dock.theta, beams=11,
                                  node="Charge", bat={"pct": 37, "charging": True,
                                                      "dock": "DOCKED"})
    messages = [map_page.map_ref(ROBOT, key, arnl_map), docked]
    with StandInMonitor({key: blob}, on_map=messages) as running:
        yield arnl_map, running


def _covered_markers(page: Page, markers: dict[str, tuple[float, float, float]]) -> list[str]:
    """The markers (name: x, y in m and radius in px) that lie under one of the map's
    controls, each with the control."""
    controls = map_page.control_boxes(page)
    covered = []
    for name, (x, y, radius) in markers.items():
        sx, sy = map_page.on_map(page, f"m.toScreen({x}, {y})")
        box = [sx - radius, sy - radius, sx + radius, sy + radius]
        covered += [f"{name} under the {control}" for control, boxes in controls.items()
                    if any(map_page.overlap(box, other) for other in boxes)]
    return covered


@pytest.mark.parametrize(("width", "height"), [(1400, 900), (390, 844)])
def test_after_fit_no_marker_lies_under_the_toolbar_or_stop(
        browser: Browser, amr_office: tuple[ArnlMap, StandInMonitor], width: int,
        height: int) -> None:
    arnl_map, server = amr_office
    errors: list[str] = []
    page = map_page.open_map_page(browser, server.url, errors, width, height)
    page.wait_for_function(f"window.__map.robot({ROBOT!r})?.pose", timeout=10000)
    server.push({"t": "seat", "may_control": True, "control": True, "holder": "this page"})
    page.wait_for_function("!document.getElementById('map-act').hidden", timeout=10000)
    robot = map_page.on_map(page, f"m.robot({ROBOT!r})")
    reach = max(abs(v) for v in robot["footprint"]) * 1.5  # the footprint's corner, at most
    markers = {item.name or item.kind: (item.x, item.y, MARKER_PX)
               for item in arnl_map.objects if item.category in MARKED}
    assert {"Dock", "room2", "room4"} <= set(markers)

    def with_robot() -> dict[str, tuple[float, float, float]]:
        scale = map_page.on_map(page, "m.view().scale")
        return {**markers, ROBOT: (robot["pose"]["x"], robot["pose"]["y"],
                                   max(7.0, reach * scale))}

    wait_until(lambda: _covered_markers(page, with_robot()) == [], 10,
               "the map fitted again once the actions' bar came")
    page.mouse.move(width / 2, height / 2)
    page.mouse.wheel(0, 600)  # zoomed out by hand, then Fit
    page.click("#map-fit")
    assert _covered_markers(page, with_robot()) == []
    screenshot(page, f"map_fit_{width}x{height}")
    assert errors == []


def test_the_free_rectangle_is_the_one_that_shows_the_map_largest(
        browser: Browser, amr_office: tuple[ArnlMap, StandInMonitor]) -> None:
    _arnl_map, server = amr_office
    errors: list[str] = []
    page = map_page.open_map_page(browser, server.url, errors)
    found = page.evaluate("""async () => {
        const { freeRect } = await import('/static/js/map/free_area.js');
        // a 400 x 600 canvas: a toolbar along the top right, STOP in the bottom right corner
        const boxes = [[250, 0, 400, 40], [330, 480, 400, 600]];
        const fit = (w, h) => (width, height) => Math.min(width / w, height / h);
        return {
            tall: freeRect(400, 600, boxes, fit(1, 2)),
            wide: freeRect(400, 600, boxes, fit(2, 1)),
            none: freeRect(400, 600, [], fit(1, 1)),
        };
    }""")
    # a tall map: beside STOP, under the toolbar, down to the bottom (scale 280, not 220)
    assert found["tall"] == {"x0": 0, "y0": 40, "x1": 330, "y1": 600}
    # a wide map: the whole width, between the toolbar and STOP (scale 200, not 165)
    assert found["wide"] == {"x0": 0, "y0": 40, "x1": 400, "y1": 480}
    assert found["none"] == {"x0": 0, "y0": 0, "x1": 400, "y1": 600}
    assert errors == []
