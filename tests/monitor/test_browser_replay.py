"""A replay is not a robot, in headless Chromium: while `cyborg play` feeds the monitor a recorded
run (a tree, its mode machine, a robot on its map), the page that holds the seat has every
control that would act on a robot disabled, each tooltip saying why, and a note above the tree
saying it in words: the map's STOP and actions (Space on the map says why and sends nothing),
the tree's Run and node hooks, the modes' Force and Hold; the player's own controls stay on.
Screenshot: replay_controls.png."""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path

import pytest
from playwright.sync_api import Browser

from cyborg.bus import BusConfig, Context, Node
from cyborg.interfaces import player as contract
from cyborg.modes import load_machine
from cyborg.monitor import Monitor
from cyborg.record.playback_source import open_recording
from cyborg.record.player import Player
from tests.builders import registry
from tests.monitor.browser import open_page, screenshot
from tests.monitor.mode_runs import write_modes
from tests.monitor.played_runs import ROBOT, TREE, write_played_run

pytestmark = pytest.mark.heavy

WHY = "off while a recording plays (cyborg play): it would act on no robot"


@pytest.fixture
def played(tmp_path: Path) -> Iterator[Monitor]:
    machine = load_machine(write_modes(tmp_path), registry=registry())
    path = tmp_path / "shift.mcap"
    write_played_run(path, json.dumps(machine.spec.to_json(), separators=(",", ":")))
    with Context(BusConfig.isolated()) as bus:
        monitor = Monitor(Node("monitor", "/cyborg", context=bus), namespaces=[TREE], port=0)
        monitor.start()
        recording = open_recording(path, bus.types)
        player = Player(Node(contract.NAME, context=bus), recording, rate=0.5, loop=True)
        try:
            yield monitor
        finally:
            player.close()
            recording.close()
            monitor.stop()


def test_controls_that_would_act_on_a_robot_are_off_while_a_recording_plays(
        browser: Browser, played: Monitor) -> None:
    errors: list[str] = []
    page = open_page(browser, f"http://127.0.0.1:{played.port}/", errors)
    page.wait_for_selector("#player-bar:not([hidden])", timeout=30000)
    page.wait_for_function("!document.getElementById('player-pause').disabled",
                           timeout=30000)  # this page holds the seat: the player's controls
    page.wait_for_function(f"window.__map && window.__map.robot({ROBOT!r})?.pose",
                           timeout=30000)
    note = page.locator("#replay-note")
    note.wait_for(state="visible", timeout=10000)
    assert "A played recording shift.mcap, not a robot" in (note.text_content() or "")
    page.wait_for_selector("#modes:not([hidden]) button[data-force]", timeout=30000)

    page.click('g.node[data-id="work"]')  # its hooks in the inspector
    off = ["#map-stop", "#map-home", "#map-goal", "#map-drive", "#run",
           "#inspector button[data-action='disable']", "#mode-hold",
           "#modes-states button[data-force]"]
    for control in off:
        locator = page.locator(control).first
        assert locator.is_disabled(), control
        assert WHY in (locator.get_attribute("title") or ""), control
    for control in ("#player-pause", "#player-step", "#player-scrub"):
        assert page.is_enabled(control), control

    sent = played.hub.robot_commands
    page.focus("#map-canvas")
    page.keyboard.press("Space")
    page.wait_for_function(f"document.getElementById('message').textContent.includes({WHY!r})",
                           timeout=10000)
    assert sent._bus == {}, "nothing was sent to a robot"
    screenshot(page, "replay_controls")
    assert errors == [], json.dumps(errors)
