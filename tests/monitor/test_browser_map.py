"""The map panel in headless Chromium (Debian's, driven by Playwright), fed by a stand-in
monitor (tests/monitor/map_page.py) that speaks the monitor's wire format: columbia.map packed
as the monitor's map blob (by the monitor's own code), and synthetic robot messages, so each
case can be made at will (test_browser_map_live.py runs the page against the real system).
What is drawn (points, walls, objects, the robot in its colour, its scan and path) in the
worker and on the main thread; zoom, pan, pinch, fit and follow; layer toggles kept; malformed
messages as warnings, never errors."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from playwright.sync_api import Browser, Page

from cyborg.nav.arnl_map import read_map
from tests.conftest import shared_dir
from tests.monitor.browser import ARTIFACTS
from tests.monitor.map_page import (
    PATH_XY,
    ROBOT,
    START,
    StandInMonitor,
    on_map,
    open_map_page,
    pixel,
    rgb,
    robot_state,
)

pytestmark = pytest.mark.heavy


def _canvas_origin(page: Page) -> tuple[float, float]:
    box = page.locator("#map-canvas").bounding_box()
    assert box is not None
    return box["x"], box["y"]


def test_columbia_robot_scan_and_path_are_drawn(browser: Browser, server: StandInMonitor,
                                                tmp_path: Path) -> None:
    errors: list[str] = []
    page = open_map_page(browser, server.url, errors)
    arnl_map = read_map(shared_dir() / "maps" / "columbia.map")
    drawn = on_map(page, "m.drawn")
    assert (drawn["points"], drawn["lines"], drawn["objects"]) == (
        len(arnl_map.points), len(arnl_map.lines), len(arnl_map.objects)) == (63311, 470, 25)
    assert on_map(page, "m.where") == "worker"
    moving = on_map(page, "m.moving")
    assert moving["robots"] == 1
    assert moving["laser"] > 400, "laser dots are drawn"
    assert moving["paths"] == len(PATH_XY) // 2
    colour = on_map(page, f"m.colourOf({ROBOT!r})")
    sx, sy = on_map(page, f"m.toScreen({START[0]}, {START[1]})")
    assert pixel(page, sx, sy) == [*rgb(colour), 255], "the robot in its colour"
    assert pixel(page, sx, sy)[:3] != pixel(page, 5, 5)[:3]
    assert page.inner_text("#map-scale .label").endswith(" m")
    assert page.is_hidden("#map-status"), "no 'no map yet' once the map is drawn"
    assert server.opted_in() is True and server.fetches == 1
    page.screenshot(path=str(tmp_path / "map_1000x600.png"))
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    page.screenshot(path=str(ARTIFACTS / "map_1000x600.png"))
    assert errors == []


def test_the_main_thread_draws_the_same_without_the_worker(
        browser: Browser, server: StandInMonitor) -> None:
    errors: list[str] = []
    page = open_map_page(browser, server.url + "?map_worker=0", errors)
    assert on_map(page, "m.where") == "main thread"
    drawn = on_map(page, "m.drawn")
    assert (drawn["points"], drawn["lines"], drawn["objects"]) == (63311, 470, 25)
    colour = on_map(page, f"m.colourOf({ROBOT!r})")
    sx, sy = on_map(page, f"m.toScreen({START[0]}, {START[1]})")
    assert pixel(page, sx, sy) == [*rgb(colour), 255]
    assert errors == []


def test_zoom_pan_pinch_fit_and_follow(browser: Browser, server: StandInMonitor) -> None:
    errors: list[str] = []
    page = open_map_page(browser, server.url, errors)
    left, top = _canvas_origin(page)
    fitted = on_map(page, "m.view()")
    renders = on_map(page, "m.renders")
    # the wheel zooms about the cursor: the world point under it stays put
    mx, my = round(left + fitted["width"] * 0.3), round(top + fitted["height"] * 0.6)
    sx, sy = mx - left, my - top  # the mouse moves on whole pixels
    under = on_map(page, f"m.toWorld({sx}, {sy})")
    page.mouse.move(mx, my)
    page.mouse.wheel(0, -400)  # far enough in that the bitmap no longer holds the whole map
    page.wait_for_function(f"window.__map.view().scale > {fitted['scale'] * 1.2}")
    zoomed = on_map(page, "m.view()")
    assert zoomed["scale"] == pytest.approx(fitted["scale"] * math.exp(0.6), rel=0.05)
    assert on_map(page, f"m.toWorld({sx}, {sy})") == pytest.approx(under, abs=1e-6)
    page.wait_for_function(f"window.__map.renders > {renders} && window.__map.drawn.points < 63311")
    # a drag pans: the world moves with the pointer
    page.mouse.move(left + 150, top + 200)
    page.mouse.down()
    page.mouse.move(left + 250, top + 250, steps=4)
    page.mouse.up()
    panned = on_map(page, "m.view()")
    assert panned["cx"] == pytest.approx(zoomed["cx"] - 100 / zoomed["scale"], abs=1e-6)
    assert panned["cy"] == pytest.approx(zoomed["cy"] + 50 / zoomed["scale"], abs=1e-6)
    # two touch pointers moving apart zoom about their midpoint
    page.evaluate("""() => {
        const canvas = document.getElementById('map-canvas'), box = canvas.getBoundingClientRect();
        const send = (type, id, x, y) => canvas.dispatchEvent(new PointerEvent(type, {
            pointerId: id, pointerType: 'touch', clientX: box.left + x, clientY: box.top + y,
            bubbles: true, isPrimary: id === 1}));
        send('pointerdown', 1, 100, 200); send('pointerdown', 2, 200, 200);
        send('pointermove', 1, 50, 200); send('pointermove', 2, 250, 200);
        send('pointerup', 1, 50, 200); send('pointerup', 2, 250, 200);
    }""")
    pinched = on_map(page, "m.view()")
    assert pinched["scale"] == pytest.approx(panned["scale"] * 2, rel=1e-6)
    # Fit shows the whole map again, as at first
    page.click("#map-fit")
    assert on_map(page, "m.view()") == pytest.approx(fitted)
    # Follow keeps the selected robot in the middle as it moves
    page.check("#map-follow")
    server.push(robot_state(ROBOT, 2, 1.5, -3.0, 0.0, st="MOVING_TO_GOAL", pid=1))
    page.wait_for_function("Math.abs(window.__map.view().cx - 1.5) < 1e-9 && "
                           "Math.abs(window.__map.view().cy + 3.0) < 1e-9")
    sx, sy = on_map(page, "m.toScreen(1.5, -3.0)")
    assert (sx, sy) == pytest.approx((fitted["width"] / 2, fitted["height"] / 2))
    page.mouse.move(left + 150, top + 200)
    page.mouse.down()
    page.mouse.move(left + 180, top + 200, steps=2)
    page.mouse.up()
    assert not page.is_checked("#map-follow"), "panning by hand stops following"
    assert errors == []


def test_layers_toggle_and_are_kept(browser: Browser, server: StandInMonitor) -> None:
    errors: list[str] = []
    page = open_map_page(browser, server.url, errors)
    page.click("#map-layers summary")
    page.uncheck("#map-layer-list input[data-layer=points]")
    page.uncheck("#map-layer-list input[data-layer=laser]")
    page.wait_for_function("window.__map.drawn.points === 0 && window.__map.moving.laser === 0")
    assert on_map(page, "m.drawn.lines") == 470
    page.reload()
    page.wait_for_function("window.__map && window.__map.firstPaint !== null")
    assert on_map(page, "m.drawn.points") == 0, "kept across a reload"
    page.click("#map-layers summary")
    assert not page.is_checked("#map-layer-list input[data-layer=points]")
    page.check("#map-layer-list input[data-layer=points]")
    page.uncheck("#map-layer-list input[data-layer=goals]")
    page.uncheck("#map-layer-list input[data-layer=forbidden]")
    page.wait_for_function("window.__map.drawn.points === 63311 && "
                           "window.__map.drawn.objects === 0")
    assert errors == []


def test_bad_messages_are_warnings_never_errors(browser: Browser,
                                                server: StandInMonitor) -> None:
    errors: list[str] = []
    page = open_map_page(browser, server.url, errors)
    server.push(
        {"t": "rs", "ns": ROBOT, "seq": 5, "p": "here"},
        {"t": "rs", "ns": ROBOT, "seq": 6, "p": [0, 0, 0],
         "sc": {"a0": 0, "da": 0.01, "mx": 30, "r": [1000, "far"]}},
        {"t": "path", "ns": ROBOT, "id": 2, "xy": [1, 2, 3]},
        "{{ not json",
        {"t": "map_ref", "ns": "/robot2", "key": "0123456789abcdef0123456789abcdef",
         "source": "broken.map", "counts": {}},
        {"t": "robot_warn", "ns": ROBOT, "kind": "pose",
         "message": "pose: x is nan; last good pose kept", "count": 3},
        {"t": "rs", "ns": ROBOT, "seq": 7, "p": [1e400, 0, 0]},
    )
    page.wait_for_function("window.__map.warnings.length >= 5")
    warnings = on_map(page, "m.warnings")
    by_kind = {w["kind"]: w for w in warnings}
    assert by_kind["bad rs"]["count"] == 2, "one row per kind, with a count"
    assert by_kind["bad rs"]["message"] == 'rs: sc.r[1] is not a number ("far"); ignored'
    assert "xy is not a list of x y pairs" in by_kind["bad path"]["message"]
    assert "could not be read" in by_kind["unreadable"]["message"]
    blob = by_kind["map 0123456789abcdef0123456789abcdef"]["message"]
    assert "broken.map could not be loaded" in blob and "CYMAP" in blob
    assert by_kind["pose"]["count"] == 3
    assert page.is_visible("#map-warnings")
    assert page.locator("#map-warning-list li").count() == len(warnings)
    page.click("#map-warnings summary")
    assert "last good pose kept (\N{MULTIPLICATION SIGN}3)" in page.inner_text(
        "#map-warning-list")
    # the panel goes on: a good message moves the robot
    server.push(robot_state(ROBOT, 8, 2.0, 1.0, 0.0))
    page.wait_for_function(f"(() => {{ const [x, y] = window.__map.toScreen(2, 1); "
                           f"const c = document.getElementById('map-canvas').getContext('2d')"
                           f".getImageData(Math.round(x * devicePixelRatio), "
                           f"Math.round(y * devicePixelRatio), 1, 1).data; "
                           f"return c[3] === 255 && '#' + [...c.slice(0, 3)].map(v => v.toString"
                           f"(16).padStart(2, '0')).join('') === "
                           f"window.__map.colourOf({ROBOT!r}); }})()")
    assert on_map(page, "m.drawn.points") == 63311
    assert errors == [], json.dumps(errors)


