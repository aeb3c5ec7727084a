"""The page around the map panel in headless Chromium: the layout (splitter and maximise kept
across reloads, phone tabs with the map first, the map's data asked for only while it can be
seen), the real monitor's page while no robot sends a map, and the figures: first paint of
columbia.map and the frame cost with three robots at 10 Hz (map_figures.json)."""

from __future__ import annotations

import json
import math
import statistics
import threading
import time
from pathlib import Path
from typing import Any

import pytest
from playwright.sync_api import Browser

from cyborg.nav.arnl_map import ArnlMap
from tests.monitor.browser import ARTIFACTS, live_system, open_page
from tests.monitor.map_page import (
    START,
    StandInMonitor,
    map_ref,
    on_map,
    open_map_page,
    robot_state,
    wait_for,
)

pytestmark = pytest.mark.heavy


def test_phone_tabs_map_first(browser: Browser, server: StandInMonitor, tmp_path: Path) -> None:
    errors: list[str] = []
    page = open_map_page(browser, server.url, errors, 390, 844)
    assert page.is_visible("#tabs")
    assert page.get_attribute("#tabs button[data-tab=map]", "aria-selected") == "true"
    assert page.is_visible("#map-view") and page.is_hidden("#view") and page.is_hidden("#side")
    toolbar = page.locator("#toolbar").bounding_box()
    assert toolbar is not None and toolbar["height"] < 60, "one scrolling row, not a wall"
    for part in (".map-tools", ".map-foot"):
        box = page.locator(part).bounding_box()
        assert box is not None and box["x"] >= 0 and box["x"] + box["width"] <= 390, part
    assert on_map(page, "m.drawn.points") == 63311
    page.screenshot(path=str(tmp_path / "map_390x844.png"))
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    page.screenshot(path=str(ARTIFACTS / "map_390x844.png"))
    page.click("#tabs button[data-tab=tree]")
    assert page.is_visible("#view") and page.is_hidden("#map-view")
    wait_for(lambda: server.opted_in() is False, 5, "the page to opt out of map data")
    page.click("#tabs button[data-tab=side]")
    assert page.is_visible("#side") and page.is_hidden("#view")
    paints = on_map(page, "m.paints")
    page.click("#tabs button[data-tab=map]")
    wait_for(lambda: server.opted_in() is True, 5, "the page to opt in again")
    page.wait_for_function(f"window.__map.paints > {paints}")
    page.reload()
    page.wait_for_function("window.__map && window.__map.firstPaint !== null")
    assert page.get_attribute("#tabs button[data-tab=map]", "aria-selected") == "true"
    assert errors == []


def test_splitter_and_maximise_are_kept(browser: Browser, server: StandInMonitor) -> None:
    errors: list[str] = []
    page = open_map_page(browser, server.url, errors)
    assert page.is_hidden("#tabs")

    def widths() -> tuple[float, float]:
        tree, map_view = (page.locator(s).bounding_box() for s in ("#view", "#map-view"))
        assert tree is not None and map_view is not None
        return tree["width"], map_view["width"]

    tree_width, map_width = widths()
    assert abs(tree_width - map_width) < 2, "half and half at first"
    box = page.locator("#splitter").bounding_box()
    assert box is not None
    x, y = box["x"] + box["width"] / 2, box["y"] + 100
    page.mouse.move(x, y)
    page.mouse.down()
    page.mouse.move(x - 100, y, steps=5)
    page.mouse.up()
    narrower, wider = widths()
    assert narrower == pytest.approx(tree_width - 100, abs=3)
    assert wider == pytest.approx(map_width + 100, abs=3)
    page.wait_for_function(f"window.__map.view().width === {wider}")  # the map follows
    page.reload()
    page.wait_for_function("window.__map && window.__map.firstPaint !== null")
    assert widths() == pytest.approx((narrower, wider), abs=1), "the share is kept"
    page.click("#map-view button[data-max=map]")
    assert page.is_hidden("#view") and page.is_visible("#map-view")
    page.reload()
    page.wait_for_function("window.__map && window.__map.firstPaint !== null")
    assert page.is_hidden("#view"), "maximised after a reload too"
    page.click("#map-view button[data-max=map]")
    assert page.is_visible("#view")
    page.click("#view button[data-max=tree]")
    assert page.is_hidden("#map-view")
    wait_for(lambda: server.opted_in() is False, 5, "no map data while the map is hidden")
    page.click("#view button[data-max=tree]")
    wait_for(lambda: server.opted_in() is True, 5, "map data again")
    assert errors == []


def test_a_monitor_without_maps_leaves_the_page_working(browser: Browser) -> None:
    with live_system(simulator=False) as live:  # a tree runner, no robot: no map
        errors: list[str] = []
        page = open_page(browser, live.url, errors)
        assert page.inner_text("#map-status") == "no map yet"
        assert page.locator("g.node").count() == 22, "the tree is drawn beside the map"
        tree, map_view = (page.locator(s).bounding_box() for s in ("#view", "#map-view"))
        assert tree is not None and map_view is not None
        assert map_view["width"] == 200 and tree["width"] > 800, "without a map, room for the tree"
        assert page.is_hidden("#splitter") and page.is_hidden("#map-fit")
        frames = page.evaluate("window.__monitor.frames")
        page.wait_for_function(f"window.__monitor.frames > {frames + 3}")
        assert "map" not in page.inner_text("#message"), "the refused opt-in is not shown"
        assert page.is_hidden("#map-warnings")
        assert errors == []


def test_first_paint_and_frame_cost(browser: Browser, columbia: tuple[ArnlMap, bytes, str],
                                    tmp_path: Path) -> None:
    """Measures what the panel costs; the figures go to map_figures.json (and the output)."""
    arnl_map, blob, key = columbia
    robots = ["/robot1", "/robot2", "/robot3"]
    first = [map_ref(ns, key, arnl_map) for ns in robots]
    first += [robot_state(ns, 1, *START) for ns in robots]
    with StandInMonitor({key: blob}, on_map=first) as server:
        paints = []
        for _ in range(5):  # a fresh context each time: a cold cache
            context = browser.new_context(viewport={"width": 1000, "height": 600})
            page = context.new_page()
            page.goto(server.url)
            page.wait_for_function("window.__map && window.__map.firstPaint !== null",
                                   timeout=20000)
            paints.append(on_map(page, "m.firstPaint - performance.timeOrigin"))
            render_ms = on_map(page, "m.drawn.ms")
            context.close()
        errors: list[str] = []
        page = open_map_page(browser, server.url, errors)
        cdp = page.context.new_cdp_session(page)
        cdp.send("Performance.enable")
        stop = threading.Event()

        def feed() -> None:  # three robots on circles at 10 Hz, each message with its scan
            seq = 2
            while not stop.is_set():
                started = time.monotonic()
                for i, ns in enumerate(robots):
                    angle = seq / 20 + i * 2.1
                    server.push(robot_state(ns, seq, 5 + 3 * math.cos(angle),
                                            3 * math.sin(angle), angle + math.pi / 2))
                seq += 1
                stop.wait(max(0.0, 0.1 - (time.monotonic() - started)))

        idle = _metrics(cdp)
        page.wait_for_timeout(3000)
        idle_end = _metrics(cdp)
        feeder = threading.Thread(target=feed, daemon=True)
        feeder.start()
        page.wait_for_timeout(1000)
        before = _metrics(cdp)
        state = on_map(page, "({paints: m.paints, frames: m.frameMs.length, messageMs: m.messageMs,"
                           " messages: m.messages})")
        page.wait_for_timeout(6000)
        after = _metrics(cdp)
        end = on_map(page, "({paints: m.paints, frameMs: m.frameMs, messageMs: m.messageMs,"
                         " messages: m.messages})")
        stop.set()
        feeder.join(5)
    frames = end["frameMs"][-(end["paints"] - state["paints"]):]
    seconds = after["Timestamp"] - before["Timestamp"]
    figures = {
        "first_paint_ms": {"median": statistics.median(paints), "runs": paints},
        "static_render_ms_in_worker": render_ms,
        "frames_per_s": len(frames) / seconds,
        "frame_ms": {"mean": statistics.fmean(frames), "p50": statistics.median(frames),
                     "p95": sorted(frames)[int(0.95 * (len(frames) - 1))], "max": max(frames)},
        "messages_per_s": (end["messages"] - state["messages"]) / seconds,
        "message_ms_per_s": (end["messageMs"] - state["messageMs"]) / seconds,
        "main_thread_ms_per_s": 1000 * (after["TaskDuration"] - before["TaskDuration"]) / seconds,
        "main_thread_ms_per_s_idle": 1000 * (idle_end["TaskDuration"] - idle["TaskDuration"])
        / (idle_end["Timestamp"] - idle["Timestamp"]),
    }
    text = json.dumps(figures, indent=1)
    print(text)
    (tmp_path / "map_figures.json").write_text(text)
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    (ARTIFACTS / "map_figures.json").write_text(text)
    assert figures["first_paint_ms"]["median"] < 3000
    assert figures["frame_ms"]["p50"] < 8
    assert 20 < figures["messages_per_s"] < 40
    assert errors == []


def _metrics(cdp: Any) -> dict[str, float]:
    found = cdp.send("Performance.getMetrics")["metrics"]
    return {item["name"]: item["value"] for item in found}


def test_the_maps_code_comes_after_the_trees_first_paint(browser: Browser) -> None:
    """The map panel's modules are fetched only once the tree is on screen (lazy_panel.js), so
    the map never delays the tree's first paint; the map is drawn all the same."""
    with live_system() as live:
        page = browser.new_page(viewport={"width": 1400, "height": 820})
        page.goto(live.url)
        page.wait_for_function("window.__map && window.__map.firstPaint !== null",
                               timeout=30000)
        first_paint = page.evaluate("window.__monitor.firstPaint - performance.timeOrigin")
        fetched: dict[str, float] = page.evaluate(  # when each file's request started (ms)
            "Object.fromEntries(performance.getEntriesByType('resource')"
            ".map(e => [e.name.split('/').pop(), e.startTime]))")
        assert "map_panel.js" in fetched and "lazy_panel.js" in fetched
        assert fetched["map_panel.js"] >= first_paint
        assert fetched["lazy_panel.js"] < first_paint
        assert page.evaluate("window.__map.drawn.points") > 0
        page.close()
