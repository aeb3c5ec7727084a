"""A red STOP stops, in headless Chromium against the real system (the simulator on the campus
map, its patrol tree and the monitor on an isolated bus): Space on the map of a page without
the seat stops the patrolling robot; the tree is halted, so no goal is sent for 30 s of
simulated time (counted on the simulator's navigate action) and the robot stands still; every
page, one opened afterwards and one of a second monitor on the same bus included, shows
"Stopped — Resume", whose Resume is off without the seat and says why; the holder's Resume
runs the patrol again, its goals come back and the banner goes from every page. Screenshot:
stopped.png."""

from __future__ import annotations

import json

import pytest
from playwright.sync_api import Browser, Page

from cyborg.bus import Node
from cyborg.monitor import Monitor
from tests.monitor.browser import Live, live_system, open_page, screenshot
from tests.running_system import wait_until

pytestmark = pytest.mark.heavy

ROBOT = "/cyborg"
TREE = "/cyborg/bt"
STILL_FOR = 30.0
"""Simulated seconds a stopped robot is watched for a goal."""
BANNER = "#stopped:not([hidden])"


def _on_map(browser: Browser, url: str, errors: list[str], *, ticking: bool = True) -> Page:
    """The monitor's page once its map is drawn with the robot on it (and, while the tree
    ticks, once ticks came)."""
    if ticking:
        page = open_page(browser, url, errors)
    else:
        page = browser.new_page(viewport={"width": 1400, "height": 820})
        page.on("pageerror", lambda error: errors.append(str(error)))
        page.goto(url)
    page.wait_for_function("window.__map && window.__map.firstPaint !== null && "
                           f"window.__map.robot({ROBOT!r})?.pose", timeout=30000)
    return page


def _goals(live: Live) -> int:
    return len(live.system.goals())


def test_stop_keeps_the_robot_stopped_until_the_seat_resumes_the_tree(browser: Browser) -> None:
    with live_system() as live:
        errors: list[str] = []
        holder = _on_map(browser, live.url, errors)
        holder.wait_for_function("window.__map.acting().canAct", timeout=30000)  # the seat
        other = _on_map(browser, live.url, errors)
        wait_until(lambda: _goals(live) >= 1 and live.system.sim.base.speed > 0.1, 60,
                   "the patrol to drive the robot to a goal")
        other.focus("#map-canvas")
        other.keyboard.press("Space")  # STOP needs no seat
        for page in (holder, other):
            page.wait_for_selector(BANNER, timeout=20000)
        other.wait_for_function("[...document.querySelectorAll('#map-log li.ok')].some(li => li"
                                f".textContent.includes('STOP — done — tree {TREE} stopped'))",
                                timeout=20000)
        wait_until(lambda: live.system.runner.stopped and not live.system.runner.enabled, 20,
                   "the tree to be stopped")
        wait_until(lambda: live.system.sim.base.speed == 0, 20, "the robot to brake")
        sent, since, where = _goals(live), live.system.sim.time, live.system.sim.pose
        wait_until(lambda: live.system.sim.time >= since + STILL_FOR, 120,
                   f"{STILL_FOR:g} s of simulated time")
        assert _goals(live) == sent, "a stopped tree sends no goal"
        assert live.system.sim.pose.distance_to(where) < 0.05, "the robot stays where it stopped"

        late = _on_map(browser, live.url, errors, ticking=False)  # one that comes later
        second = Monitor(Node("second_monitor", "/cyborg", context=live.system.context),
                         namespaces=[TREE], port=0)  # another monitor on the same bus
        second.start()
        try:
            afar = _on_map(browser, f"http://127.0.0.1:{second.port}/", errors, ticking=False)
            pages = (holder, other, late, afar)
            for page in pages:
                page.wait_for_selector(BANNER, timeout=20000)
                text = page.text_content("#stopped") or ""
                assert f"{ROBOT} stopped" in text and TREE in text and "Resume" in text, text
            for page in (other, late):
                assert page.is_disabled("#stopped button[data-resume]")
                title = page.get_attribute("#stopped button[data-resume]", "title") or ""
                assert "take control" in title, title
            assert not holder.is_disabled("#stopped button[data-resume]")
            screenshot(other, "stopped")

            holder.click("#stopped button[data-resume]")
            wait_until(lambda: _goals(live) > sent, 60, "the patrol to send its next goal")
            assert live.system.runner.enabled and not live.system.runner.stopped
            for page in pages:
                page.wait_for_selector("#stopped", state="hidden", timeout=20000)
        finally:
            second.stop()
        assert errors == [], json.dumps(errors)


def test_a_stop_from_another_page_ends_a_drive_by_hand_whose_key_is_still_held(
        browser: Browser) -> None:
    with live_system() as live:
        errors: list[str] = []
        driver = _on_map(browser, live.url, errors)
        driver.wait_for_function("window.__map.acting().canAct", timeout=30000)  # the seat
        other = _on_map(browser, live.url, errors)
        sim = live.system.sim
        driver.focus("#map-canvas")
        driver.keyboard.down("ArrowLeft")  # turning on the spot, held from now on
        wait_until(lambda: sim.base.turn_rate > 0.1, 30, "the robot to turn by hand")
        other.click("#map-stop")
        wait_until(lambda: sim.base.turn_rate == 0 and sim.base.speed == 0, 20,
                   "the robot to stop")
        heading, since = sim.pose.theta, sim.time
        wait_until(lambda: sim.time >= since + 10.0, 60, "10 s of simulated time")
        assert sim.pose.theta == heading, "the held key drives no more"
        driver.wait_for_function("[...document.querySelectorAll('#map-log li.error')].some("
                                 "li => li.textContent.includes('drive refused'))",
                                 timeout=20000)
        driver.keyboard.up("ArrowLeft")
        driver.keyboard.down("ArrowLeft")  # pressed again: it drives again
        wait_until(lambda: sim.pose.theta != heading, 30, "the robot to turn again")
        driver.keyboard.up("ArrowLeft")
        assert errors == [], json.dumps(errors)
