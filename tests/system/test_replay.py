"""A run recorded with ``cyborg up --record``, played again with ``cyborg play``: the monitor
(in headless Chromium) shows it as it showed it live — the tree ticking, the campus map drawn
from the played, latched map and the robot on it at its played pose. Screenshot:
replay_campus.png in the test artifacts."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
from playwright.sync_api import Browser

from cyborg.bus import BusConfig, Context, Node
from cyborg.monitor import Monitor
from cyborg.nav.arnl_map import read_map
from tests.monitor.browser import CAMPUS_MAP, open_page, screenshot
from tests.monitor.map_page import on_map
from tests.ports import free_port

pytestmark = pytest.mark.heavy

ROBOT = "/cyborg"


def test_the_monitor_shows_a_played_run_as_it_showed_it_live(browser: Browser,
                                                             tmp_path: Path) -> None:
    path = tmp_path / "up.mcap"
    recorded = subprocess.run(
        [sys.executable, "-m", "cyborg", "up", "--no-detector", "--no-monitor", "--record",
         str(path), "--duration", "6", "--listen", f"tcp/127.0.0.1:{free_port()}"],
        capture_output=True, text=True, timeout=180, check=False)
    assert recorded.returncode == 0, recorded.stderr
    address = f"tcp/127.0.0.1:{free_port()}"
    with Context(BusConfig.router([address])) as bus:
        monitor = Monitor(Node("monitor", "/cyborg", context=bus), namespaces=["/cyborg/bt"],
                          port=0)
        monitor.start()
        player = subprocess.Popen(
            [sys.executable, "-m", "cyborg", "play", str(path), "--loop", "--connect", address],
            stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        try:
            errors: list[str] = []
            page = open_page(browser, f"http://127.0.0.1:{monitor.port}/", errors)  # ticks
            page.wait_for_function(
                "window.__map && window.__map.firstPaint !== null && "
                f"window.__map.robot({ROBOT!r})?.pose", timeout=60000)
            campus = read_map(CAMPUS_MAP)
            drawn = on_map(page, "m.drawn")
            assert (drawn["points"], drawn["lines"], drawn["objects"]) == (
                len(campus.points), len(campus.lines), len(campus.objects))
            pose = on_map(page, f"m.robot({ROBOT!r}).pose")
            min_x, min_y, max_x, max_y = campus.bounds()
            assert min_x <= pose["x"] <= max_x and min_y <= pose["y"] <= max_y, pose
            screenshot(page, "replay_campus")
            assert player.poll() is None, player.communicate()[1]
            assert not errors, errors
        finally:
            player.terminate()
            _out, err = player.communicate(timeout=60)
            monitor.stop()
    assert "played" in err, err
