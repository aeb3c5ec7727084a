"""Three robots in the monitor, in headless Chromium (Debian's, driven by Playwright), against
the real system `cyborg up --robots 3` starts: the simulated fleet on the campus map, a tree
runner per robot and the monitor. All three are on the map, each in its own colour with its
name and its laser mounted through its own frames; the robot selector shows each robot's
swatch in the map's colour, switches the tree shown (the page's Pause reaches that robot's
runner) and the robot the map follows; a click on a robot on the map selects it; and the page
goes on across a restart of the fleet. Screenshots: fleet_map.png, fleet_robot2_followed.png,
fleet_restarted.png."""

from __future__ import annotations

import json
import math
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any

import pytest
from playwright.sync_api import Browser, Page

from cyborg.app.cli import build_parser
from cyborg.app.launch import Launch
from cyborg.app.up import up_description
from cyborg.bus import BusConfig, Context
from cyborg.monitor.component import RunningMonitor
from cyborg.runner.component import RunningTree
from cyborg.sim import component as sim
from cyborg.sim.component import RunningFleet
from tests.monitor.browser import open_page, screenshot
from tests.monitor.map_page import on_map, pixel, rgb
from tests.running_system import wait_until

pytestmark = pytest.mark.heavy

ROBOTS = ["/robot1", "/robot2", "/robot3"]


@dataclass
class Fleet:
    context: Context
    launch: Launch

    @property
    def url(self) -> str:
        [running] = [item for item in self.launch.running if isinstance(item, RunningMonitor)]
        return f"http://127.0.0.1:{running.monitor.port}/"

    @property
    def simulator(self) -> RunningFleet:
        [running] = [item for item in self.launch.running if isinstance(item, RunningFleet)]
        return running

    def runner(self, robot: str) -> RunningTree:
        [running] = [item for item in self.launch.running if isinstance(item, RunningTree)
                     and item.runner.node.namespace == f"{robot}/bt"]
        return running

    def restart_simulator(self) -> None:
        old = self.simulator
        old.stop()
        self.launch.running.remove(old)

    def start_simulator(self) -> None:
        [spec] = [spec for spec in self.launch.description.nodes if spec.kind == "simulator"]
        self.launch.running.append(sim.start(self.context, spec))


@contextmanager
def fleet_system() -> Iterator[Fleet]:
    args = build_parser().parse_args(["up", "--robots", "3", "--no-detector", "--speed", "10",
                                      "--monitor-port", "0"])
    with Context(BusConfig.isolated()) as context:
        launch = Launch(up_description(args), context)
        launch.start()
        try:
            yield Fleet(context, launch)
        finally:
            launch.stop()


def _robot(page: Page, ns: str) -> dict[str, Any]:
    found: dict[str, Any] = on_map(page, f"m.robot({ns!r})")
    return found


def _all_on_the_map(page: Page, alive: bool = True) -> None:
    page.wait_for_function(
        "window.__map && window.__map.firstPaint !== null && "
        + " && ".join(f"window.__map.robot({ns!r})?.pose && window.__map.robot({ns!r}).alive "
                      f"=== {str(alive).lower()}" for ns in ROBOTS), timeout=60000)


def _canvas_origin(page: Page) -> tuple[float, float]:
    box = page.locator("#map-canvas").bounding_box()
    assert box is not None
    return box["x"], box["y"]


def _zoom_on(page: Page, ns: str) -> tuple[float, float]:
    """Zooms the map in about the robot ``ns``; where it is on the canvas then."""
    page.click("#map-fit")
    at = _robot(page, ns)["pose"]
    sx, sy = on_map(page, f"m.toScreen({at['x']}, {at['y']})")
    left, top = _canvas_origin(page)
    page.mouse.move(left + round(sx), top + round(sy))
    while on_map(page, "m.view().scale") < 60:
        page.mouse.wheel(0, -300)
        page.wait_for_timeout(50)
    page.wait_for_timeout(200)  # drawn at that scale
    found: tuple[float, float] = tuple(on_map(page, f"m.toScreen({at['x']}, {at['y']})"))
    return found


def test_three_robots_each_in_its_colour_selected_from_the_list_or_the_map(
        browser: Browser) -> None:
    with fleet_system() as fleet:
        errors: list[str] = []
        page = open_page(browser, fleet.url, errors)
        _all_on_the_map(page)
        page.wait_for_function("window.__map.moving.robots === 3 && "
                               "window.__map.moving.names === 3", timeout=20000)
        colours = [on_map(page, f"m.colourOf({ns!r})") for ns in ROBOTS]
        assert len(set(colours)) == 3, colours
        shown = [_robot(page, ns) for ns in ROBOTS]
        assert all(robot["mount"] == [0.267, 0, 0] for robot in shown), \
            "each scan's frame (robot1/laser ...) resolved through /tf_static"
        # the selector: one entry per robot, its swatch in the map's colour
        options = page.eval_on_selector_all(
            "#robot option", "os => os.map(o => [o.value, o.dataset.robot, o.dataset.colour, "
                             "o.textContent])")
        assert [option[:3] for option in options] == [
            [f"{ns}/bt", ns, colour] for ns, colour in zip(ROBOTS, colours, strict=True)]
        assert all(option[3].startswith(f"● {ns} — ") for option, ns in zip(options, ROBOTS,
                                                                            strict=True))
        # still, each robot is drawn in its colour where the page has it (zoomed in on it, so
        # that a neighbour queueing close by, or its name, does not cover it)
        with fleet.simulator.loop.lock:
            page.wait_for_timeout(400)  # the last poses are on screen
            screenshot(page, "fleet_map")
            for ns, colour in zip(ROBOTS, colours, strict=True):
                sx, sy = _zoom_on(page, ns)
                assert pixel(page, sx, sy) == [*rgb(colour), 255], ns
            page.click("#map-fit")
        # choosing robot2 in the list: its tree is shown (Pause reaches its runner), the map
        # follows it, the swatch takes its colour
        page.check("#map-follow")
        page.select_option("#robot", "/robot2/bt")
        page.wait_for_function("window.__map.selected() === '/robot2'", timeout=10000)
        assert page.evaluate("getComputedStyle(document.getElementById('robot-swatch'))"
                             ".backgroundColor") == "rgb({}, {}, {})".format(*rgb(colours[1]))
        page.wait_for_function("document.getElementById('run').disabled === false",
                               timeout=10000)
        page.click("#run")
        wait_until(lambda: not fleet.runner("/robot2").runner.enabled, 10, "robot2's tree paused")
        assert fleet.runner("/robot1").runner.enabled and fleet.runner("/robot3").runner.enabled
        page.wait_for_function(
            "(() => { const v = window.__map.view(), p = window.__map.robot('/robot2').pose; "
            "return Math.hypot(v.cx - p.x, v.cy - p.y) < 0.05; })()", timeout=10000)
        screenshot(page, "fleet_robot2_followed")
        # a click on robot3 on the map selects it, and shows its tree
        left, top = _canvas_origin(page)
        page.uncheck("#map-follow")
        with fleet.simulator.loop.lock:
            page.wait_for_timeout(400)
            at = _robot(page, "/robot3")["pose"]
            sx, sy = on_map(page, f"m.toScreen({at['x']}, {at['y']})")
            page.mouse.click(left + sx, top + sy)
        page.wait_for_function("window.__map.selected() === '/robot3'", timeout=10000)
        page.wait_for_function("document.getElementById('robot').value === '/robot3/bt'",
                               timeout=10000)
        page.wait_for_function("document.getElementById('run').textContent.includes('Pause')",
                               timeout=10000)  # robot3's tree runs; robot2's was paused
        assert on_map(page, "m.warnings") == []
        assert errors == [], json.dumps(errors)


def test_the_page_goes_on_across_a_restart_of_the_fleet(browser: Browser) -> None:
    with fleet_system() as fleet:
        errors: list[str] = []
        page = open_page(browser, fleet.url, errors)
        _all_on_the_map(page)
        colours = [on_map(page, f"m.colourOf({ns!r})") for ns in ROBOTS]
        fleet.restart_simulator()
        _all_on_the_map(page, alive=False)
        page.wait_for_function("window.__map.moving.laser === 0", timeout=10000)  # none left
        fleet.start_simulator()
        _all_on_the_map(page)
        before = {ns: _robot(page, ns)["pose"] for ns in ROBOTS}

        def all_moved() -> bool:
            return all(math.hypot(_robot(page, ns)["pose"]["x"] - before[ns]["x"],
                                  _robot(page, ns)["pose"]["y"] - before[ns]["y"]) > 0.3
                       for ns in ROBOTS)
        wait_until(all_moved, 90, "every restarted robot to drive again on the page")
        assert [on_map(page, f"m.colourOf({ns!r})") for ns in ROBOTS] == colours
        assert on_map(page, "m.fetches") == 1, "the map was not fetched again"
        assert page.locator("#robot option").count() == 3
        screenshot(page, "fleet_restarted")
        assert on_map(page, "m.warnings") == []
        assert errors == [], json.dumps(errors)
