"""Acting from the map against the real system, in headless Chromium: the simulator on the
campus map, its patrol tree and the monitor on an isolated bus. The page takes control; a
click on the goal "Office" on the map sends the robot there, the tree is shown paused for the
manual goal and Resume runs it again; a drag with "Set pose" relocalises the robot with the
heading of the drag; Stop ends a goal sent with "Go to pose"; a page without the seat has its
tools disabled and says why, but its Stop works; a tour of two clicked points is driven to the
end; the arrow keys and the joystick drive the robot, which stops when they are let go.
Screenshots: acting_goal.png, acting_stop.png, acting_phone.png, acting_tour.png."""

from __future__ import annotations

import json
import math
from typing import Any

import pytest
from playwright.sync_api import Browser, Page

from tests.monitor.browser import Live, live_system, open_page, screenshot
from tests.monitor.map_page import on_map
from tests.running_system import wait_until

pytestmark = pytest.mark.heavy

ROBOT = "/cyborg"
OFFICE = (11.0, 3.0)
"""The campus map's goal "Office"."""
LIBRARY = (15.0, 11.0)
"""The campus map's goal "Library"."""
CORRIDOR = (17.0, 7.0)
"""A free spot in the campus corridor (its goal "Corridor")."""


def _acting_page(browser: Browser, live: Live, errors: list[str]) -> Page:
    """The monitor's page once its map is drawn, the robot is on it and the page may act."""
    page = open_page(browser, live.url, errors)
    page.wait_for_function("window.__map && window.__map.firstPaint !== null && "
                           f"window.__map.robot({ROBOT!r})?.pose && "
                           "window.__map.acting().canAct", timeout=30000)
    return page


def _acting(page: Page) -> dict[str, Any]:
    found: dict[str, Any] = on_map(page, "m.acting()")
    return found


def _canvas_point(page: Page, x: float, y: float) -> tuple[float, float]:
    """Where the world point (x, y) is on the page, in CSS px."""
    box = page.locator("#map-canvas").bounding_box()
    assert box is not None
    sx, sy = on_map(page, f"m.toScreen({x}, {y})")
    return box["x"] + sx, box["y"] + sy


def _bring_to_middle(page: Page, x: float, y: float) -> tuple[float, float]:
    """Pans the map (a drag from its middle) until the world point (x, y) is in the middle,
    clear of the map's buttons; returns where it is on the page."""
    box = page.locator("#map-canvas").bounding_box()
    assert box is not None
    middle = (box["x"] + box["width"] / 2, box["y"] + box["height"] / 2)
    at = _canvas_point(page, x, y)
    page.mouse.move(*middle)
    page.mouse.down()
    page.mouse.move(middle[0] + middle[0] - at[0], middle[1] + middle[1] - at[1], steps=8)
    page.mouse.up()
    at = _canvas_point(page, x, y)
    assert math.hypot(at[0] - middle[0], at[1] - middle[1]) < 2, (at, middle)
    return at


def _drag(page: Page, start: tuple[float, float], end: tuple[float, float]) -> None:
    page.mouse.move(*start)
    page.mouse.down()
    page.mouse.move(*end, steps=10)
    page.mouse.up()


def _log(page: Page) -> list[str]:
    rows: list[str] = page.eval_on_selector_all("#map-log li", "items => items.map("
                                                "i => `${i.className}: ${i.textContent}`)")
    return rows


def _distance(live: Live, x: float, y: float) -> float:
    pose = live.system.sim.pose
    return math.hypot(pose.x - x, pose.y - y)


def test_a_click_on_a_goal_sends_the_robot_there_and_the_tree_waits(browser: Browser) -> None:
    with live_system() as live:
        errors: list[str] = []
        page = _acting_page(browser, live, errors)
        assert _acting(page)["robot"] == ROBOT, "the robot of the shown tree"
        wait_until(lambda: live.system.runner.enabled, 10, "the patrol to run")
        at = _bring_to_middle(page, *OFFICE)
        page.mouse.move(*at)
        assert page.get_attribute("#map-canvas", "title") == ("Office: click to send /cyborg to "
                                                              "Office")
        page.mouse.click(*at)
        page.wait_for_selector("#manual-pause", state="visible", timeout=20000)
        assert "Tree paused for a manual goal" in page.inner_text("#manual-pause")
        assert not live.system.runner.enabled, "the patrol waits while the operator drives"
        assert page.inner_text("#run") == "▶ Run"
        wait_until(lambda: _distance(live, *OFFICE) < 0.5, 120, "the robot to reach Office")
        page.wait_for_function("[...document.querySelectorAll('#map-log li.ok')].some("
                               "li => li.textContent.includes(\"'Office' reached\"))",
                               timeout=30000)
        screenshot(page, "acting_goal")
        page.click("#manual-resume")
        wait_until(lambda: live.system.runner.enabled, 20, "Resume to run the tree again")
        page.wait_for_selector("#manual-pause", state="hidden", timeout=20000)
        assert errors == [], json.dumps(errors)


def test_set_pose_by_dragging_and_stop_ending_a_goal(browser: Browser) -> None:
    with live_system() as live:
        errors: list[str] = []
        page = _acting_page(browser, live, errors)
        page.click("#run")  # pause the patrol, so the robot stays where it is put
        wait_until(lambda: not live.system.runner.enabled, 20, "the tree to pause")
        at = _bring_to_middle(page, *CORRIDOR)
        page.click("#map-act button[data-tool='set']")
        assert _acting(page)["mode"] == "set"
        _drag(page, at, (at[0], at[1] - 60))  # up on screen: north, heading π/2
        wait_until(lambda: _distance(live, *CORRIDOR) < 0.15, 20, "the robot to be put there")
        heading = live.system.sim.pose.theta
        assert abs(math.remainder(heading - math.pi / 2, math.tau)) < 0.05, heading
        assert _acting(page)["mode"] is None, "one use, then the map pans again"
        page.wait_for_function("[...document.querySelectorAll('#map-log li.ok')].some("
                               "li => li.textContent.includes('set pose (17.0'))",
                               timeout=20000)
        # go to a pose far east, then stop on the way
        page.click("#map-act button[data-tool='pose']")
        target = _canvas_point(page, CORRIDOR[0] + 8.0, CORRIDOR[1])
        _drag(page, target, (target[0] + 40, target[1]))
        wait_until(lambda: _distance(live, *CORRIDOR) > 0.3, 60, "the robot to set off")
        page.click("#map-stop")
        page.wait_for_function("[...document.querySelectorAll('#map-log li.error')].some("
                               "li => li.textContent.includes('failed'))", timeout=30000)
        wait_until(lambda: live.system.sim.base.speed == 0, 20, "the robot to brake")
        stopped = live.system.sim.pose
        page.wait_for_timeout(500)
        moved = math.hypot(live.system.sim.pose.x - stopped.x, live.system.sim.pose.y - stopped.y)
        assert moved < 0.05, "the robot stays stopped"
        assert any("STOP" in row for row in _log(page)), _log(page)
        screenshot(page, "acting_stop")
        assert errors == [], json.dumps(errors)


def test_a_phone_takes_control_and_taps_a_goal_and_a_page_without_the_seat_stops_it(
        browser: Browser) -> None:
    with live_system() as live:
        errors: list[str] = []
        desk = _acting_page(browser, live, errors)
        phone_context = browser.new_context(viewport={"width": 390, "height": 760},
                                            has_touch=True, is_mobile=True)
        phone = phone_context.new_page()
        phone.on("console", lambda message: errors.append(message.text)
                 if message.type == "error" else None)
        phone.on("pageerror", lambda error: errors.append(str(error)))
        phone.goto(live.url)
        phone.wait_for_function("window.__map && window.__map.firstPaint !== null && "
                                f"window.__map.robot({ROBOT!r})?.pose", timeout=30000)
        assert _acting(phone)["canAct"] is False, "the desk page holds the seat"
        assert phone.is_disabled("#map-home") and phone.is_disabled("#map-goal")
        assert "take control" in (phone.get_attribute("#map-home", "title") or "")
        assert phone.is_visible("#map-stop") and not phone.is_disabled("#map-stop")
        phone.click("#take")
        phone.wait_for_function("window.__map.acting().canAct", timeout=20000)
        desk.wait_for_function("!window.__map.acting().canAct", timeout=20000)
        assert desk.is_disabled("#map-home") and not desk.is_disabled("#map-stop")
        # a goal away from the robot: its marker lies over the goal it stands at, and takes the tap
        name, goal = max((("Library", LIBRARY), ("Office", OFFICE)),
                         key=lambda item: _distance(live, *item[1]))
        phone.touchscreen.tap(*_canvas_point(phone, *goal))
        wait_until(lambda: not live.system.runner.enabled, 20, "the tapped goal to pause the tree")
        start = live.system.sim.pose
        wait_until(lambda: _distance(live, start.x, start.y) > 0.3, 60, "the robot to set off")
        screenshot(phone, "acting_phone")
        desk.click("#map-stop")  # no seat, and yet it stops the robot
        phone.wait_for_function("[...document.querySelectorAll('#map-log li.error')].some("
                                f"li => li.textContent.includes(\"'{name}' failed\"))",
                                timeout=30000)
        box = phone.locator("#map-stop").bounding_box()
        assert box is not None and box["x"] + box["width"] <= 390, "Stop fits a phone"
        phone_context.close()
        assert errors == [], json.dumps(errors)


def test_a_tour_of_clicked_points_then_driving_by_keys_and_joystick(browser: Browser) -> None:
    with live_system() as live:
        errors: list[str] = []
        page = _acting_page(browser, live, errors)
        middle = _bring_to_middle(page, (OFFICE[0] + CORRIDOR[0]) / 2,
                                  (OFFICE[1] + CORRIDOR[1]) / 2)
        page.click("#map-act button[data-tool='tour']")
        for point in (OFFICE, CORRIDOR):
            page.mouse.click(*_canvas_point(page, *point))
        drawn = _acting(page)["points"]
        assert len(drawn) == 2 and all(th is None for _x, _y, th in drawn)
        for (x, y, _th), (want_x, want_y) in zip(drawn, (OFFICE, CORRIDOR), strict=True):
            assert math.hypot(x - want_x, y - want_y) < 0.2
        assert page.inner_text("#map-tour-go") == "Go (2)"
        page.click("#map-tour-go")
        page.wait_for_function("[...document.querySelectorAll('#map-log li.ok')].some("
                               "li => li.textContent.includes('tour, done'))", timeout=120000)
        assert _distance(live, *CORRIDOR) < 0.5
        assert not live.system.runner.enabled, "the tour paused the patrol"
        screenshot(page, "acting_tour")
        # the arrow keys, while the map has focus
        page.mouse.click(*middle)
        start = live.system.sim.pose
        page.keyboard.down("ArrowLeft")  # turn on the spot
        wait_until(lambda: abs(math.remainder(live.system.sim.pose.theta - start.theta,
                                              math.tau)) > 0.3, 30, "the robot to turn")
        page.keyboard.up("ArrowLeft")
        wait_until(lambda: live.system.sim.base.turn_rate == 0, 10, "the robot to stop turning")
        # the joystick: pushed up, the robot drives forwards
        page.click("#map-drive")
        pad = page.locator("#map-joystick").bounding_box()
        assert pad is not None
        centre = (pad["x"] + pad["width"] / 2, pad["y"] + pad["height"] / 2)
        start = live.system.sim.pose
        page.mouse.move(*centre)
        page.mouse.down()
        page.mouse.move(centre[0], centre[1] - pad["height"] / 4, steps=4)
        wait_until(lambda: _distance(live, start.x, start.y) > 0.2, 30, "the robot to drive")
        page.mouse.up()
        wait_until(lambda: live.system.sim.base.speed == 0, 10, "the robot to stop on release")
        assert errors == [], json.dumps(errors)
