"""A stream of hostile robot messages never breaks the page: a monitor on an isolated bus
follows a good robot on a small map and a hostile one (/bad) that publishes random, malformed
messages of every kind (tests/monitor/hostile_messages.py) for several seconds, while headless
Chromium shows the map; the page logs no console error, keeps drawing the good robot as it
moves, and lists the hostile robot's faults as warnings."""

from __future__ import annotations

import json
import random
import time

import pytest
from playwright.sync_api import Browser

from cyborg.bus import BusConfig, Context, Node
from cyborg.monitor import Monitor
from tests.monitor.hostile_messages import KINDS, hostile_message, publish
from tests.monitor.map_page import on_map, open_map_page
from tests.monitor.robot_messages import FakeMapRobot, map_geometry, pose
from tests.running_system import wait_until

pytestmark = pytest.mark.heavy

STORM_S = 4.0


def test_a_stream_of_hostile_messages_never_breaks_the_page(browser: Browser) -> None:
    with Context(BusConfig.isolated()) as context:
        monitor = Monitor(Node("monitor", "/cyborg", context=context), port=0)
        good = FakeMapRobot(Node("arnl", "/robot1", context=context))
        bad = FakeMapRobot(Node("bad", "/bad", context=context), "/bad")
        monitor.start()
        try:
            good.map.publish(map_geometry())
            errors: list[str] = []
            page = open_map_page(browser, f"http://127.0.0.1:{monitor.port}/", errors)

            def placed() -> bool:  # poses are not latched: again until one is followed
                good.pose.publish(pose(1.0, 1.0, 0.0))
                return bool(on_map(page, "m.robot('/robot1')?.pose"))

            wait_until(placed, 30.0, "the good robot on the page")
            rng = random.Random(21)
            start, step = time.monotonic(), 0
            paints = on_map(page, "m.paints")
            while time.monotonic() - start < STORM_S:
                step += 1
                for _ in range(5):
                    kind = rng.choice(KINDS)
                    publish(bad, kind, hostile_message(rng, kind))
                good.pose.publish(pose(1.0 + step / 100, 1.0, 0.0))
                time.sleep(0.03)
            x = round(1.0 + step / 100, 3)
            page.wait_for_function(f"Math.abs(window.__map.robot('/robot1').pose.x - {x}) "
                                   "< 1e-6", timeout=15000)
            assert on_map(page, "m.paints") > paints + 20, "the map kept drawing"
            assert on_map(page, "m.drawn.lines") == 2, "the good robot's map is still shown"
            kinds = {w["kind"] for w in on_map(page, "m.warnings") if w["ns"] == "/bad"}
            assert len(kinds) >= 5, f"the hostile robot's faults are listed: {sorted(kinds)}"
            assert not any(w["kind"].startswith("bad ") or w["kind"] == "unreadable"
                           for w in on_map(page, "m.warnings")), \
                "every message the monitor sent was one the page could read"
            assert errors == [], json.dumps(errors)
        finally:
            monitor.stop()
