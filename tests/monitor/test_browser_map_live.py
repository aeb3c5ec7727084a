"""The map panel against the real system, in headless Chromium (Debian's, driven by Playwright):
the simulator on the bundled campus map, the tree runner driving its patrol and the monitor, on
an isolated bus. The campus map is drawn with its counts; the robot is at its simulated pose in
its colour, with its laser (through the mount from /tf_static), its footprint, its battery and
its planned path; a restarted simulator is followed without fetching the map again; a bad
publisher under another namespace yields warnings on the page, never a console error.
Screenshots go to the test artifacts (map_campus.png, map_simulator_gone.png,
map_bad_publisher.png)."""

from __future__ import annotations

import json
import math
import urllib.request
from typing import Any

import numpy as np
import pytest
from playwright.sync_api import Browser, Page

from cyborg.bus import Node
from cyborg.interfaces import robot
from cyborg.nav.arnl_map import read_map
from tests.monitor.browser import (
    CAMPUS_MAP,
    Live,
    live_system,
    open_page,
    screenshot,
)
from tests.monitor.map_page import on_map, pixel, rgb
from tests.monitor.robot_messages import map_geometry, pose, scan
from tests.running_system import wait_until

pytestmark = pytest.mark.heavy

ROBOT = "/cyborg"


def _open(browser: Browser, live: Live, errors: list[str]) -> Page:
    """The monitor's page, once its map is drawn and the robot is on it."""
    page = open_page(browser, live.url, errors)
    page.wait_for_function("window.__map && window.__map.firstPaint !== null && "
                           f"window.__map.robot({ROBOT!r})?.pose", timeout=30000)
    return page


def _robot(page: Page, ns: str = ROBOT) -> dict[str, Any]:
    found: dict[str, Any] = on_map(page, f"m.robot({ns!r})")
    return found


def _stats(live: Live) -> dict[str, Any]:
    with urllib.request.urlopen(live.url + "stats", timeout=10) as answer:
        found: dict[str, Any] = json.load(answer)
    return found


def _driving(page: Page, timeout: float = 60000) -> None:
    """Waits until the tree drives the robot: a path is drawn and the laser's hits are."""
    page.wait_for_function("window.__map.moving.paths > 1 && window.__map.moving.laser > 100",
                           timeout=timeout)


def _moved_from(page: Page, x: float, y: float, metres: float, timeout: float = 60000) -> None:
    page.wait_for_function(f"(() => {{ const p = window.__map.robot({ROBOT!r})?.pose; return p "
                           f"&& Math.hypot(p.x - {x}, p.y - {y}) > {metres}; }})()",
                           timeout=timeout)


def test_the_campus_map_and_the_robot_on_its_patrol(browser: Browser) -> None:
    campus = read_map(CAMPUS_MAP)
    with live_system() as live:
        errors: list[str] = []
        page = _open(browser, live, errors)
        drawn = on_map(page, "m.drawn")
        assert (drawn["points"], drawn["lines"], drawn["objects"]) == (
            len(campus.points), len(campus.lines), len(campus.objects))
        assert on_map(page, "m.fetches") == 1 and _stats(live)["map_fetches"] == 1
        _driving(page)
        shown = _robot(page)
        sim = live.system.sim
        assert shown["mount"] == [sim.laser.spec.mount_x, 0, 0], "the mount from /tf_static"
        assert shown["footprint"] == pytest.approx(
            sim.base.footprint.polygon().reshape(-1).tolist(), abs=1e-3), "the sim's footprint"
        assert 0 < shown["battery"]["pct"] <= 100 and shown["battery"]["dock"] == "UNDOCKED"
        assert shown["state"] == "MOVING_TO_GOAL" and shown["path"] > 1 and shown["scan"] > 100
        assert shown["alive"] is True
        # the tree and the map speak: the running MoveTo beside the robot, its goal ringed
        page.wait_for_function(f"(() => {{ const r = window.__map.robot({ROBOT!r}); return "
                               "r.goal !== null && r.node === 'MoveTo ' + r.goal.name; })()")
        goal = on_map(page, f"m.robot({ROBOT!r}).goal")
        where = {item.name: (item.x, item.y) for item in campus.objects if item.name}
        assert (goal["x"], goal["y"]) == pytest.approx(where[goal["name"]], abs=0.002), \
            "the current goal where the map has it"
        assert on_map(page, "m.moving.goals") == 1
        screenshot(page, "map_campus")
        # pause the tree: the robot stops, and the page shows it where the simulator has it
        page.click("#run")
        wait_until(lambda: not live.system.runner.enabled, 10, "the tree to pause")
        _wait_still(page, live)
        at = _robot(page)["pose"]
        true = live.system.sim.base.pose
        assert (at["x"], at["y"]) == pytest.approx((true.x, true.y), abs=0.002)
        assert at["th"] == pytest.approx(math.remainder(true.theta, math.tau), abs=0.002)
        sx, sy = on_map(page, f"m.toScreen({at['x']}, {at['y']})")
        page.wait_for_timeout(100)  # the frame with that pose is on screen
        assert pixel(page, sx, sy) == [*rgb(_robot(page)["colour"]), 255], "robot in its colour"
        assert on_map(page, "m.moving.laser") > 100
        assert errors == [], json.dumps(errors)


def _wait_still(page: Page, live: Live) -> None:
    """Waits until the page's pose of the robot is the simulator's, and stays so for 0.5 s."""
    def same() -> bool:
        at = _robot(page)["pose"]
        true = live.system.sim.base.pose
        return bool(math.hypot(at["x"] - true.x, at["y"] - true.y) < 0.002)

    wait_until(same, 30, "the robot to stop where the page shows it")
    start = _robot(page)["pose"]
    page.wait_for_timeout(500)
    if _robot(page)["pose"] != start:
        _wait_still(page, live)


def test_a_restarted_simulator_is_followed_without_fetching_the_map_again(
        browser: Browser) -> None:
    with live_system() as live:
        errors: list[str] = []
        page = _open(browser, live, errors)
        first = _robot(page)["pose"]
        _moved_from(page, first["x"], first["y"], 0.5)
        fetched = _stats(live)["map_fetches"]
        assert fetched == 1
        path_id = _robot(page)["pathId"]
        live.system.stop_simulator()
        page.wait_for_function(f"window.__map.robot({ROBOT!r}).alive === false", timeout=20000)
        assert on_map(page, "m.moving.laser") == 0, "a robot that left shows no laser"
        screenshot(page, "map_simulator_gone")
        live.system.start_simulator()
        page.wait_for_function(f"window.__map.robot({ROBOT!r}).alive === true", timeout=20000)
        page.wait_for_function(f"window.__map.robot({ROBOT!r}).pathId > {path_id}",
                               timeout=60000)  # the new simulator's first path
        again = _robot(page)["pose"]
        _moved_from(page, again["x"], again["y"], 0.5)
        _driving(page)
        assert _stats(live)["map_fetches"] == fetched, "the map was not fetched again"
        assert on_map(page, "m.fetches") == 1
        page.reload()
        page.wait_for_function("window.__map && window.__map.firstPaint !== null",
                               timeout=30000)
        assert _stats(live)["map_fetches"] == fetched, "a reload takes the map from the cache"
        assert on_map(page, "m.warnings") == []
        assert errors == [], json.dumps(errors)


def test_a_bad_publisher_yields_warnings_not_errors(browser: Browser) -> None:
    with live_system() as live:
        errors: list[str] = []
        page = _open(browser, live, errors)
        node = Node("bad", "/bad", context=live.system.context)
        absurd = robot.MAP_GEOMETRY.publisher(node)
        poses, scans = robot.POSE.publisher(node), robot.SCAN.publisher(node)
        absurd.publish(map_geometry(points=np.array([1.0, 2.0, 1e12, 3.0], np.float32)))
        short = scan(np.full(100, 1.0, np.float32), beams=100,
                     angle_max=-math.radians(135) + math.radians(0.5) * 540)

        def warned() -> bool:
            poses.publish(pose(math.nan, 1.0, 0.0))
            scans.publish(short)
            kinds = {w["kind"] for w in on_map(page, "m.warnings") if w["ns"] == "/bad"}
            return kinds >= {"map", "pose", "scan"}

        wait_until(warned, 30, "the page to warn about /bad's map, pose and scan")
        warnings = {w["kind"]: w["message"] for w in on_map(page, "m.warnings")
                    if w["ns"] == "/bad"}
        assert "1e+12 m from the origin" in warnings["map"]
        assert warnings["pose"] == "pose: x is nan; last good pose kept"
        assert warnings["scan"].startswith("scan: 100 ranges where")
        assert all(w["ns"] == "/bad" for w in on_map(page, "m.warnings")), \
            "nothing else is wrong: the page read every message of the monitor"
        assert page.is_visible("#map-warnings")
        page.click("#map-warnings summary")
        assert "/bad pose: x is nan" in page.inner_text("#map-warning-list")
        assert _robot(page, "/bad") is None, "nothing of /bad could be drawn"
        assert _robot(page)["colour"] == "#1a73e8", "the campus robot keeps its colour"
        first = _robot(page)["pose"]
        _moved_from(page, first["x"], first["y"], 0.3)  # the campus robot goes on
        screenshot(page, "map_bad_publisher")
        node.destroy()
        assert errors == [], json.dumps(errors)
