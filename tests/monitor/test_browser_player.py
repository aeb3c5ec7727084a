"""A recorded run played into the monitor, scrubbed from its page in headless Chromium: the bar
under the tree shows the whole recording (file, position of duration as m:ss); pause, seek
back (dragging the slider, seeking on release) and step go to the player, and the tree view
(node statuses, the tick in the status line) and the robot on the map follow the played time;
a second page sees the position with its controls disabled and a tooltip saying why.
Screenshot: player_timeline.png in the test artifacts."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest
from playwright.sync_api import Browser, Page

from cyborg.bus import BusConfig, Context, Node
from cyborg.interfaces import player as contract
from cyborg.monitor import Monitor
from cyborg.record.playback_source import open_recording
from cyborg.record.player import Player
from tests.monitor.browser import open_page, screenshot
from tests.monitor.map_page import on_map
from tests.monitor.played_runs import ROBOT, TREE, write_played_run

pytestmark = pytest.mark.heavy


@pytest.fixture
def played(tmp_path: Path) -> Iterator[tuple[Monitor, Player]]:
    path = tmp_path / "shift.mcap"
    write_played_run(path)
    with Context(BusConfig.isolated()) as bus:
        monitor = Monitor(Node("monitor", "/cyborg", context=bus), namespaces=[TREE], port=0)
        monitor.start()
        recording = open_recording(path, bus.types)
        player = Player(Node(contract.NAME, context=bus), recording, rate=0.5)
        try:
            yield monitor, player
        finally:
            player.close()
            recording.close()
            monitor.stop()


def _status(page: Page, node: str) -> str:
    classes: str = page.get_attribute(f'g.node[data-id="{node}"]', "class") or ""
    return next((name for name in classes.split() if name in ("s1", "s2", "s3", "never")),
                "")


def _wait_status(page: Page, node: str, wanted: str) -> None:
    page.wait_for_function(
        f"""(() => {{ const g = document.querySelector('g.node[data-id="{node}"]');
              return g && g.classList.contains({wanted!r}); }})()""", timeout=30000)


def test_the_page_scrubs_a_played_recording_and_the_tree_and_map_follow(
        browser: Browser, played: tuple[Monitor, Player]) -> None:
    monitor, player = played
    errors: list[str] = []
    page = open_page(browser, f"http://127.0.0.1:{monitor.port}/", errors)
    page.wait_for_selector("#player-bar:not([hidden])", timeout=30000)
    # (" · ended" follows when a loaded machine opened the page after the 8 s of play)
    assert (page.text_content("#player-file") or "").startswith("shift.mcap x0.5")
    assert page.is_hidden("#history") and page.is_hidden("#scrub"), "the history gives way"
    page.wait_for_function("!document.getElementById('player-pause').disabled",
                           timeout=30000)  # this page took the seat
    assert page.text_content("#player-time", timeout=5000).endswith(" / 0:04")  # type: ignore[union-attr]
    _wait_status(page, "rest", "s3")  # played past halfway: work done, rest running
    assert _status(page, "work") == "s1"

    page.click("#player-pause")
    page.wait_for_function("document.getElementById('player-pause').textContent.includes('Play')",
                           timeout=30000)
    assert player.paused

    # drag the thumb back to 1.05 s: the time under it shows, the seek goes on release
    page.evaluate("""() => { const s = document.getElementById('player-scrub');
        s.value = '1.05'; s.dispatchEvent(new Event('input', {bubbles: true})); }""")
    assert page.text_content("#player-time") == "→ 0:01 / 0:04"
    page.evaluate("""() => document.getElementById('player-scrub')
        .dispatchEvent(new Event('change', {bubbles: true}))""")
    page.wait_for_function("document.getElementById('player-time').textContent === '0:01 / 0:04'"
                           " && Number(document.getElementById('player-scrub').value) === 1.05",
                           timeout=30000)
    assert player.paused and player.position == pytest.approx(1.05)
    _wait_status(page, "work", "s3")  # the tree as it was at 1.05 s, not as 3 s left it
    assert _status(page, "rest") == "never"
    page.wait_for_function("document.getElementById('tickinfo').textContent.includes('tick 10 ')",
                           timeout=30000)
    page.wait_for_function(f"window.__map && window.__map.robot({ROBOT!r})?.pose?.x === 1",
                           timeout=30000)

    page.click("#player-step")  # the next message: the tick at 1.1 s
    page.wait_for_function("document.getElementById('tickinfo').textContent.includes('tick 11 ')",
                           timeout=30000)
    assert player.paused and player.position == pytest.approx(1.1)
    page.focus("#player-scrub")
    page.keyboard.press("Home")
    page.wait_for_function("document.getElementById('player-time').textContent === '0:00 / 0:04'",
                           timeout=30000)
    assert player.position == 0.0
    # nothing has run before the recording's first message: the tree starts over
    page.wait_for_function("document.getElementById('tickinfo').textContent.includes('tick 0 ')",
                           timeout=30000)
    assert {_status(page, node) for node in ("root", "work", "rest")} == {"never"}
    assert on_map(page, "m.firstPaint !== null")
    screenshot(page, "player_timeline")

    other = browser.new_page()  # on the same machine, but the seat is taken
    other.on("pageerror", lambda error: errors.append(str(error)))
    other.goto(f"http://127.0.0.1:{monitor.port}/")
    other.wait_for_selector("#player-bar:not([hidden])", timeout=30000)
    other.wait_for_function("document.getElementById('player-time').textContent === '0:00 / 0:04'",
                            timeout=30000)
    for control in ("#player-pause", "#player-step", "#player-scrub"):
        assert other.is_disabled(control), control
        assert (other.get_attribute(control, "title") or "").startswith("Another page has control")
    assert not errors, errors
