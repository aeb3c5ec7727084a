"""The robot selector and the selected robot (js/robots.js), in headless Chromium against a
stand-in monitor that speaks the monitor's protocol: every robot is listed with its colour
swatch (a robot without a tree runner too), a robot keeps its colour when others join, and a
robot is selected from the list or by a click on it on the map (a drag that starts on it pans
instead), which asks the monitor for that robot's tree."""

from __future__ import annotations

import json
from typing import Any

import pytest
from playwright.sync_api import Browser, Page

from cyborg.nav.arnl_map import ArnlMap
from tests.monitor.map_page import (
    ROBOT,
    START,
    StandInMonitor,
    map_ref,
    on_map,
    open_map_page,
    robot_state,
    wait_for,
)

pytestmark = pytest.mark.heavy

OTHER = "/robot2"
OTHER_AT = (START[0] + 2.0, START[1], 0.0)


def _robots(key: str, *extra: str) -> dict[str, Any]:
    """The monitor's ``robots`` message: robot1 driven by /robot1/bt, robot2 by no runner."""
    robots = [{"ns": ROBOT, "tree": f"{ROBOT}/bt", "alive": True, "map": key},
              {"ns": OTHER, "tree": None, "alive": True, "map": key}]
    robots += [{"ns": ns, "tree": None, "alive": True, "map": key} for ns in extra]
    return {"t": "robots", "robots": [{"ns": f"{ROBOT}/bt", "title": "Patrol", "alive": True}],
            "map_robots": robots}


def _options(page: Page) -> list[list[str]]:
    found: list[list[str]] = page.eval_on_selector_all(
        "#robot option", "os => os.map(o => [o.value, o.dataset.robot || '', "
                         "o.dataset.colour || '', o.textContent])")
    return found


def _watched(server: StandInMonitor) -> list[str]:
    return [message["ns"] for message in server.received if message.get("t") == "watch"]


def _click_robot(page: Page, ns: str, drag: float = 0.0) -> None:
    at = on_map(page, f"m.robot({ns!r}).pose")
    sx, sy = on_map(page, f"m.toScreen({at['x']}, {at['y']})")
    box = page.locator("#map-canvas").bounding_box()
    assert box is not None
    x, y = box["x"] + sx, box["y"] + sy
    if drag:
        page.mouse.move(x, y)
        page.mouse.down()
        page.mouse.move(x + drag, y, steps=5)
        page.mouse.up()
    else:
        page.mouse.click(x, y)


def test_robots_are_listed_in_their_colours_and_selected_from_the_list_or_the_map(
        browser: Browser, server: StandInMonitor, columbia: tuple[ArnlMap, bytes, str]) -> None:
    arnl_map, _blob, key = columbia
    errors: list[str] = []
    page = open_map_page(browser, server.url, errors)
    server.push(_robots(key), map_ref(OTHER, key, arnl_map), robot_state(OTHER, 1, *OTHER_AT))
    page.wait_for_function(f"window.__map.robot({OTHER!r})?.pose && "
                           "document.querySelectorAll('#robot option').length === 2")
    blue, orange = on_map(page, f"m.colourOf({ROBOT!r})"), on_map(page, f"m.colourOf({OTHER!r})")
    assert (blue, orange) == ("#1a73e8", "#e8710a")
    assert _options(page) == [[f"{ROBOT}/bt", ROBOT, blue, f"● {ROBOT} — Patrol"],
                              [f"{OTHER}/bt", OTHER, orange, f"● {OTHER}"]]
    # a robot that sorts first joins: nobody's colour changes
    server.push(_robots(key, "/a"), map_ref("/a", key, arnl_map),
                robot_state("/a", 1, START[0], START[1] - 2.0, 0.0))
    page.wait_for_function("document.querySelectorAll('#robot option').length === 3")
    assert on_map(page, "m.robot('/a').colour") == "#188038"
    assert [on_map(page, f"m.colourOf({ns!r})") for ns in (ROBOT, OTHER)] == [blue, orange]
    # a drag that starts on robot2 pans the map and selects nothing; a click selects it
    before = on_map(page, "m.selected()")
    _click_robot(page, OTHER, drag=40)
    page.wait_for_timeout(200)
    assert on_map(page, "m.selected()") == before != OTHER
    _click_robot(page, OTHER)
    page.wait_for_function(f"window.__map.selected() === {OTHER!r}")
    assert page.input_value("#robot") == f"{OTHER}/bt"
    wait_for(lambda: _watched(server)[-1:] == [f"{OTHER}/bt"], 10, "the watch of robot2's tree")
    assert page.evaluate("getComputedStyle(document.getElementById('robot-swatch'))"
                         ".backgroundColor") == "rgb(232, 113, 10)"
    # the list selects too
    page.select_option("#robot", f"{ROBOT}/bt")
    page.wait_for_function(f"window.__map.selected() === {ROBOT!r}")
    wait_for(lambda: _watched(server)[-1:] == [f"{ROBOT}/bt"], 10, "the watch of robot1's tree")
    assert errors == [], json.dumps(errors)
