"""The tree's first paint in headless Chromium, read from a performance trace: the tree's nodes
are styled and laid out once per drawing, by the browser's own frame, never by a layout that the
page's script forces.

A forced layout right after the tree's markup went in laid out every box and every label
(fit() asked the view's size), labels the fit then hid as too small to read; on a 1,000-node
tree that took longer than drawing the tree. It happens when the tree arrives before the page
has had a frame (the page's modules still loading while the WebSocket, opened by index.html,
already holds the structure), so one load here delays the page's code to make that order
certain. Counts, not timings: they do not depend on how busy the machine is.
"""

from __future__ import annotations

import json
import time
from collections.abc import Iterator
from typing import Any

import pytest
from playwright.sync_api import Browser, Route

from cyborg.bus import BusConfig, Context, Node
from cyborg.monitor import Monitor
from cyborg.runner.tree_runner import TreeRunnerNode
from tests.builders import N, tree_json
from tests.monitor.browser import WHOLE_TREE

pytestmark = pytest.mark.heavy

BRANCHES, LEAVES = 20, 15
"""A wide tree (321 nodes): fitted, its labels are too small to read and are left out."""
SCRIPT = ("FunctionCall", "EvaluateScript", "FireAnimationFrame", "TimerFire", "EventDispatch",
          "v8.callFunction", "v8.evaluateModule")
"""Trace events in which the page's script runs: a layout inside one was forced by it."""
CATEGORIES = ["devtools.timeline", "disabled-by-default-devtools.timeline",
              "blink.user_timing", "v8.execute"]


@pytest.fixture(scope="module")
def monitor_url(tmp_path_factory: pytest.TempPathFactory) -> Iterator[str]:
    wide = N("MemSequence", *(N("Sequence", *(N("Wait", milliseconds=100 + 50 * (leaf % 4))
                                             for leaf in range(LEAVES)))
                              for _ in range(BRANCHES)))
    path = tmp_path_factory.mktemp("tree") / "wide.b3.json"
    path.write_text(json.dumps(tree_json(N("Repeater", wide, maxLoop=-1))))
    with Context(BusConfig.isolated()) as context:
        runner = TreeRunnerNode(Node("tree_runner", "/wide/bt", context=context), path,
                                rate_hz=10.0)
        monitor = Monitor(Node("monitor", "/wide", context=context), namespaces=["/wide/bt"],
                          host="127.0.0.1", port=0)
        runner.start()
        monitor.start()
        try:
            yield monitor.urls()[0]
        finally:
            monitor.stop()
            runner.destroy()


def traced_first_paint(browser: Browser, url: str, *,
                       code_late: bool) -> tuple[int, int, list[dict[str, Any]]]:
    """Loads the page under a trace until the tree's first paint: the nodes drawn, how often
    the page drew the tree (a snapshot arriving a frame after the structure draws it again),
    and the style recalculations and layouts on the page's main thread until then, each with
    ``size`` (elements styled, objects laid out) and ``forced`` (inside the page's script).
    ``code_late``: app.js comes 0.5 s late, so the tree is waiting when the code starts."""
    context = browser.new_context(viewport={"width": 1400, "height": 820})
    page = context.new_page()
    page.add_init_script(WHOLE_TREE)  # every node drawn, fitted: labels too small are left out
    if code_late:
        def late(route: Route) -> None:
            response = route.fetch()
            time.sleep(0.5)
            route.fulfill(response=response)
        page.route("**/static/js/app.js", late)
    browser.start_tracing(page=page, categories=CATEGORIES)
    try:
        page.goto(url)
        page.wait_for_function("window.__monitor && window.__monitor.firstPaint !== null",
                               timeout=30000)
        first_paint_ms = page.evaluate("window.__monitor.firstPaint - performance.timeOrigin")
        drawn, draws = page.evaluate("[window.__monitor.drawn, window.__monitor.draws]")
    finally:
        trace = json.loads(browser.stop_tracing())["traceEvents"]
        context.close()
    start = [event for event in trace if event.get("name") == "navigationStart"
             and url in json.dumps(event.get("args", {}))][-1]
    end = start["ts"] + first_paint_ms * 1000
    main = [event for event in trace if event.get("pid") == start["pid"]
            and event.get("tid") == start["tid"] and start["ts"] <= event.get("ts", 0) <= end
            and event.get("ph") == "X"]
    script = [(event["ts"], event["ts"] + event.get("dur", 0)) for event in main
              if event["name"] in SCRIPT]
    passes = []
    for event in main:
        if event["name"] == "Layout":
            size = event["args"]["beginData"]["dirtyObjects"]
        elif event["name"] == "UpdateLayoutTree":
            size = event["args"].get("elementCount", 0)
        else:
            continue
        forced = any(begin <= event["ts"] <= finish for begin, finish in script)
        passes.append({"name": event["name"], "size": size, "forced": forced})
    return drawn, draws, passes


@pytest.mark.parametrize("code_late", [True, False], ids=["tree-before-code", "as-it-comes"])
def test_the_tree_is_laid_out_once_by_the_frame(browser: Browser, monitor_url: str,
                                                code_late: bool) -> None:
    drawn, draws, passes = traced_first_paint(browser, monitor_url, code_late=code_late)
    assert drawn > BRANCHES * LEAVES, "the whole tree is drawn"
    of_the_tree = [p for p in passes if p["size"] >= drawn]
    assert [p for p in of_the_tree if p["forced"]] == [], (
        f"the page's script forced a style recalculation or layout of the tree: {passes}")
    layouts = [p for p in of_the_tree if p["name"] == "Layout"]
    styles = [p for p in of_the_tree if p["name"] == "UpdateLayoutTree"]
    assert 1 <= len(layouts) <= draws and 1 <= len(styles) <= draws, (
        f"each of the {draws} drawings of the tree is styled and laid out once: {passes}")
