"""The tree and the map speak to each other, in headless Chromium against the stand-in monitor
(tests/monitor/map_page.py): the running node is written beside the robot, the current goal is
ringed with its name, and selecting a node that names a goal (MoveTo's ``location``) rings
that goal on the map and brings it into view (also from under STOP); selecting another node
clears it."""

from __future__ import annotations

import json
from typing import Any

import pytest
from playwright.sync_api import Browser, Page

from tests.monitor.map_page import (
    GOAL_1,
    ROBOT,
    START,
    StandInMonitor,
    control_boxes,
    on_map,
    open_map_page,
    overlap,
    pixel,
    robot_state,
)

pytestmark = pytest.mark.heavy

TREE_NS = ROBOT + "/bt"
WORKSHOP = (13.02, -12.197)
"""A goal of columbia.map far from the robot."""
HIGHLIGHT = [0xF9, 0xAB, 0x00]


def _node(uid: str, name: str, label: str, category: str, properties: dict[str, Any],
          *children: dict[str, Any]) -> dict[str, Any]:
    return {"id": uid, "node_id": uid, "name": name, "title": label, "label": label,
            "category": category, "depth": 0, "index": 0, "properties": properties,
            "children": list(children)}


def _show_tree(server: StandInMonitor) -> None:
    """The stand-in speaks for a tree runner under /robot1/bt: its structure and state."""
    root = _node("seq", "MemSequence", "MemSequence", "composite", {},
                 _node("to_goal_1", "MoveTo", "MoveTo Goal 1", "action",
                       {"location": "Goal 1", "radius": 0.5}),
                 _node("to_workshop", "MoveTo", "MoveTo Workshop", "action",
                       {"location": "Workshop", "radius": 0.5}),
                 _node("wait", "Wait", "Wait 2000ms", "action", {"milliseconds": 2000}),
                 _node("custom", "Deliver", "Deliver parcel", "action",
                       {"parcel": 7, "destination": "Lobby door"}))
    server.push({"t": "watching", "ns": TREE_NS},
                {"t": "runner", "ns": TREE_NS, "alive": True, "enabled": True, "hooks": [],
                 "paused_at": "", "problem": ""},
                {"t": "structure", "ns": TREE_NS, "v": "v1",
                 "tree": {"schema": "cyborg.bt.structure/1", "title": "errands", "root": root}},
                {"t": "snapshot", "ns": TREE_NS, "v": "v1", "seq": 1, "tick": 1, "time": 0.1,
                 "dur": 0.1, "root": 3, "codes": [3 + 8, 3 + 8, 0, 0, 0],
                 "act": [0, 1]})


def _ink(page: Page, x0: float, y0: float, x1: float, y1: float) -> int:
    """How many pixels of the map's upper canvas in the box (CSS px) are drawn on."""
    found: int = page.evaluate("""([x0, y0, x1, y1]) => {
        const canvas = document.getElementById('map-canvas'), dpr = devicePixelRatio;
        const data = canvas.getContext('2d').getImageData(Math.round(x0 * dpr),
            Math.round(y0 * dpr), Math.round((x1 - x0) * dpr), Math.round((y1 - y0) * dpr)).data;
        let n = 0;
        for (let i = 3; i < data.length; i += 4) if (data[i] > 0) n += 1;
        return n;
    }""", [x0, y0, x1, y1])
    return found


def _close(found: list[int], wanted: list[int], tolerance: int = 40) -> bool:
    return all(abs(a - b) <= tolerance for a, b in zip(found[:3], wanted, strict=True))


def test_the_running_node_and_the_current_goal_are_drawn(browser: Browser,
                                                         server: StandInMonitor) -> None:
    errors: list[str] = []
    page = open_map_page(browser, server.url, errors)
    page.wait_for_function(f"window.__map.robot({ROBOT!r})?.node === 'MoveTo Goal 1'")
    page.click("#map-layers summary")
    for layer in ("laser", "paths", "points", "walls"):  # only the robot, its goal, the texts
        page.uncheck(f"#map-layer-list input[data-layer={layer}]")
    page.click("#map-layers summary")
    page.wait_for_function("window.__map.moving.laser === 0 && window.__map.moving.paths === 0")
    robot = on_map(page, f"m.robot({ROBOT!r})")
    assert robot["goal"] == {"name": "Goal 1", "x": GOAL_1[0], "y": GOAL_1[1], "th": 0.0,
                             "heading": True}
    assert on_map(page, "m.moving.goals") == 1
    colour = robot["colour"]
    gx, gy = on_map(page, f"m.toScreen({GOAL_1[0]}, {GOAL_1[1]})")
    rgb = [int(colour[i:i + 2], 16) for i in (1, 3, 5)]
    assert _close(pixel(page, gx, gy - 10), rgb), "the goal's ring in the robot's colour"
    assert _ink(page, gx - 30, gy + 13, gx + 30, gy + 26) > 20, "the goal's name under it"
    [name] = [found for found in on_map(page, "m.labels()") if found["kind"] == "robot"]
    assert name["text"].endswith(" / MoveTo Goal 1"), "the running node under the robot's name"
    label = (name["x0"], (name["y0"] + name["y1"]) / 2, name["x1"], name["y1"])  # its 2nd line
    assert _ink(page, *label) > 20, "the running node written beside the robot"
    server.push(robot_state(ROBOT, 2, *START, st="MOVING_TO_GOAL", pid=1, node="",
                            goal=None))
    page.wait_for_function(f"window.__map.robot({ROBOT!r}).node === ''")
    page.wait_for_function("window.__map.moving.goals === 0")
    assert _ink(page, *label) == 0, "no node runs: nothing written"
    assert errors == []


def test_selecting_a_node_that_names_a_goal_rings_it_on_the_map(
        browser: Browser, server: StandInMonitor) -> None:
    errors: list[str] = []
    page = open_map_page(browser, server.url, errors)
    _show_tree(server)
    page.wait_for_selector('g.node[data-id="to_goal_1"]')
    page.click('g.node[data-id="to_goal_1"]')
    page.wait_for_function("window.__map.highlight()?.name === 'Goal 1'")
    view = on_map(page, "m.view()")
    gx, gy = on_map(page, f"m.toScreen({GOAL_1[0]}, {GOAL_1[1]})")
    page.wait_for_timeout(1800)  # the pulse is over: the steady ring stays
    assert _close(pixel(page, gx, gy - 16), HIGHLIGHT), "the goal ringed"
    assert on_map(page, "m.view()") == view, "a goal on screen: the view stays"
    # zoom in far from the workshop, then select the MoveTo that goes there
    box = page.locator("#map-canvas").bounding_box()
    assert box is not None
    page.mouse.move(box["x"] + 20, box["y"] + 20)
    for _ in range(4):
        page.mouse.wheel(0, -400)
    page.wait_for_function(f"window.__map.view().scale > {view['scale'] * 4}")
    wx, wy = on_map(page, f"m.toScreen({WORKSHOP[0]}, {WORKSHOP[1]})")
    assert not (0 <= wx <= view["width"] and 0 <= wy <= view["height"]), "off screen first"
    page.click('g.node[data-id="to_workshop"]')
    page.wait_for_function("window.__map.highlight()?.name === 'Workshop'")
    wx, wy = on_map(page, f"m.toScreen({WORKSHOP[0]}, {WORKSHOP[1]})")
    shown = on_map(page, "m.view()")
    assert (wx, wy) == pytest.approx((shown["width"] / 2, shown["height"] / 2), abs=1), \
        "the view pans to the goal"
    page.wait_for_timeout(1800)
    assert _close(pixel(page, wx, wy - 16), HIGHLIGHT)
    # a node of another kind whose properties name a goal
    page.click('g.node[data-id="custom"]')
    page.wait_for_function("window.__map.highlight()?.name === 'Lobby door'")
    # a node that names no goal clears it
    page.click('g.node[data-id="wait"]')
    page.wait_for_function("window.__map.highlight() === null")
    lx, ly = on_map(page, "m.toScreen(-1.86, -22.44)")
    page.wait_for_timeout(100)
    assert not _close(pixel(page, lx, ly - 16), HIGHLIGHT), "the ring is gone"
    assert errors == [], json.dumps(errors)


def test_selecting_a_goal_hidden_under_stop_brings_it_out(browser: Browser,
                                                          server: StandInMonitor) -> None:
    errors: list[str] = []
    page = open_map_page(browser, server.url, errors)
    _show_tree(server)
    page.wait_for_selector('g.node[data-id="to_goal_1"]')
    # drag the map until Goal 1 lies under STOP
    [stop] = control_boxes(page)["stop"]
    box = page.locator("#map-canvas").bounding_box()
    assert box is not None
    gx, gy = on_map(page, f"m.toScreen({GOAL_1[0]}, {GOAL_1[1]})")
    start = (box["x"] + box["width"] / 2, box["y"] + box["height"] / 2)
    page.mouse.move(*start)
    page.mouse.down()
    target = ((stop[0] + stop[2]) / 2, (stop[1] + stop[3]) / 2)
    page.mouse.move(start[0] + target[0] - gx, start[1] + target[1] - gy, steps=4)
    page.mouse.up()
    gx, gy = on_map(page, f"m.toScreen({GOAL_1[0]}, {GOAL_1[1]})")
    assert overlap([gx - 5, gy - 5, gx + 5, gy + 5], stop), "under STOP first"
    page.click('g.node[data-id="to_goal_1"]')
    page.wait_for_function("window.__map.highlight()?.name === 'Goal 1'")
    view = on_map(page, "m.view()")
    assert on_map(page, f"m.toScreen({GOAL_1[0]}, {GOAL_1[1]})") == pytest.approx(
        [view["width"] / 2, view["height"] / 2], abs=1), "the view pans to the goal"
    assert errors == []
