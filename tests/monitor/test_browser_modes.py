"""The Modes panel in headless Chromium, against a tree runner serving a mode file: the machine's
states with the current one highlighted; forcing a mode from the page switches the panel and
the tree view (the tree entered shows none of the statuses of the tree left, and a tree shown
again gets its folds back); the hold shows as held, to other pages too, whose controls are
disabled with a tooltip saying why; a mode file that fails to reload shows its problems; with
a dozen modes no two labels overlap. Screenshots: modes_panel.png, modes_twelve.png."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from playwright.sync_api import Browser, Page

from cyborg.bt import TreeLoadError
from cyborg.bus import BusConfig, Context, Node
from cyborg.monitor import Monitor
from cyborg.runner.tree_runner import TreeRunnerNode
from tests.monitor.browser import screenshot
from tests.monitor.mode_runs import NAMESPACE, mode_names, start_runner, title_of

pytestmark = pytest.mark.heavy


@pytest.fixture
def bus() -> Iterator[Context]:
    with Context(BusConfig.isolated()) as context:
        yield context


@pytest.fixture
def monitor(bus: Context) -> Iterator[Monitor]:
    monitor = Monitor(Node("monitor", "/cyborg", context=bus), namespaces=[NAMESPACE], port=0)
    monitor.start()
    try:
        yield monitor
    finally:
        monitor.stop()


def _runner(bus: Context, folder: Path, count: int) -> TreeRunnerNode:
    return start_runner(bus, folder, count)


def _open(browser: Browser, monitor: Monitor, errors: list[str]) -> Page:
    """A page on the monitor recording console errors, once its Modes panel is shown (the
    runner is paused: no ticks to wait for)."""
    page = browser.new_page(viewport={"width": 1400, "height": 820})
    page.on("console", lambda message: errors.append(message.text)
            if message.type == "error" else None)
    page.on("pageerror", lambda error: errors.append(str(error)))
    page.goto(f"http://127.0.0.1:{monitor.port}/")
    page.wait_for_selector("#modes:not([hidden])", timeout=30000)
    return page


def _current(page: Page, mode: str) -> None:
    page.wait_for_selector(f'#modes-states li.mode-state.current[data-mode="{mode}"]',
                           timeout=30000)


def _class_of(page: Page, node: str) -> str:
    return page.get_attribute(f'g.node[data-id="{node}"]', "class") or ""


def test_the_panel_shows_the_machine_forces_holds_and_shows_a_bad_file(
        browser: Browser, bus: Context, monitor: Monitor, tmp_path: Path) -> None:
    runner = _runner(bus, tmp_path, 4)
    errors: list[str] = []
    try:
        for _ in range(2):
            runner.runner.step()  # Patrol's act runs
        page = _open(browser, monitor, errors)
        _current(page, "normal")
        states = page.eval_on_selector_all("#modes-states li.mode-state",
                                           "items => items.map(i => i.dataset.mode)")
        assert states == ["*", "normal", "low", "critical", "demo"]
        assert "initial" in (page.text_content('li.mode-state[data-mode="normal"]') or "")
        arrows = page.text_content('li.mode-state[data-mode="normal"] ul.mode-arrows') or ""
        assert "low" in arrows and "battery.percent < 20" in arrows and "request" in arrows
        assert "after 60 s" in (page.text_content('li.mode-state[data-mode="demo"]') or "")
        page.wait_for_function("document.getElementById('tree-mode').textContent"
                               ".startsWith('mode normal · Patrol')", timeout=30000)
        page.wait_for_function(
            "document.querySelector('g.node[data-id=\"act\"]')?.classList.contains('s3')",
            timeout=30000)
        page.dblclick('g.node[data-id="root"]')  # Patrol's root folded by hand
        page.wait_for_function("document.querySelector('g.node[data-id=\"root\"]')"
                               "?.classList.contains('folded')", timeout=30000)

        force = 'li.mode-state[data-mode="low"] button[data-force]'
        page.wait_for_selector(f"{force}:not([disabled])", timeout=30000)  # it took the seat
        assert page.is_disabled('li.mode-state[data-mode="normal"] button[data-force]')
        page.click(force)
        _current(page, "low")
        page.wait_for_function("document.getElementById('tree-mode').textContent"
                               ".startsWith('mode low · Go charge')", timeout=30000)
        classes = _class_of(page, "act")
        assert "s3" not in classes and "never" in classes, \
            f"the entered tree shows no status of the tree left: {classes}"
        assert "folded" not in _class_of(page, "root"), "Go charge has its own folds"
        recent = page.text_content("#modes-recent li") or ""
        assert "normal → low" in recent and "forced from the monitor" in recent
        runner.runner.step()  # Go charge's first tick
        page.wait_for_function(
            "document.querySelector('g.node[data-id=\"act\"]')?.classList.contains('s3')",
            timeout=30000)

        page.click("#mode-hold")
        page.wait_for_selector('li.mode-state.held[data-mode="low"]', timeout=30000)
        assert "held" in (page.text_content("#modes-current") or "")
        assert (page.text_content("#mode-hold") or "") == "Release hold"
        assert runner.ticked.held  # type: ignore[union-attr]

        other = _open(browser, monitor, errors)
        other.wait_for_selector('li.mode-state.held[data-mode="low"]', timeout=30000)
        assert other.is_disabled("#mode-hold")
        why = other.get_attribute('li.mode-state[data-mode="critical"] button[data-force]',
                                  "title") or ""
        assert "take control" in why, why
        other.close()

        page.click('li.mode-state[data-mode="normal"] button[data-force]')
        _current(page, "normal")
        page.wait_for_function("document.querySelector('g.node[data-id=\"root\"]')"
                               "?.classList.contains('folded')", timeout=30000)  # folds back

        bad = tmp_path / "bad.modes.toml"
        bad.write_text('project = "mission.b3.json"\ninitial = "normal"\n[modes.normal]\n'
                       'tree = "Go charging"\n')
        with pytest.raises(TreeLoadError):
            runner.reload(bad)
        page.wait_for_selector("#modes-problems:not([hidden])", timeout=30000)
        problems = page.text_content("#modes-problems") or ""
        assert f"{bad}:4" in problems and "mode 'normal'" in problems, problems
        assert page.locator("#modes-states li.mode-state").count() == 5, "still drawn"
        screenshot(page, "modes_panel")
        assert not errors, errors
    finally:
        runner.destroy()


def _overlaps(boxes: list[dict[str, Any]]) -> list[tuple[str, str]]:
    found = []
    for index, one in enumerate(boxes):
        for two in boxes[index + 1:]:
            wide = min(one["right"], two["right"]) - max(one["left"], two["left"])
            high = min(one["bottom"], two["bottom"]) - max(one["top"], two["top"])
            if wide > 0.5 and high > 0.5:
                found.append((one["text"], two["text"]))
    return found


def test_a_dozen_modes_keep_their_labels_readable(
        browser: Browser, bus: Context, monitor: Monitor, tmp_path: Path) -> None:
    runner = _runner(bus, tmp_path, 12)
    errors: list[str] = []
    try:
        page = _open(browser, monitor, errors)
        page.wait_for_function(
            "document.querySelectorAll('#modes-states li.mode-state').length === 13",
            timeout=30000)
        boxes: list[dict[str, Any]] = page.eval_on_selector_all(
            "#modes-states .mode-name, #modes-states .mode-tree, #modes-states .mode-tag, "
            "#modes-states .mode-target, #modes-states .mode-trigger, #modes-states button",
            """items => items.map(i => { const r = i.getBoundingClientRect();
                 const style = getComputedStyle(i);
                 return {text: i.textContent, left: r.left, right: r.right, top: r.top,
                         bottom: r.bottom, size: parseFloat(style.fontSize),
                         clipped: i.scrollWidth > i.clientWidth + 1}; })""")
        names = [box["text"] for box in boxes if box["text"] in mode_names(12)]
        assert len(set(names)) == 12, names
        assert all(box["right"] - box["left"] > 0 for box in boxes), "every label laid out"
        assert not _overlaps(boxes), _overlaps(boxes)
        assert min(box["size"] for box in boxes) >= 11, "no label shrunk to fit"
        titles = {box["text"] for box in boxes}
        assert all(title_of(mode) in titles for mode in mode_names(12)), "titles whole"
        assert not [box["text"] for box in boxes if box["clipped"]
                    and box["text"] in mode_names(12)], "no mode name cut"
        side = page.eval_on_selector("#side", "s => s.scrollWidth <= s.clientWidth + 1")
        assert side, "the panel does not run out of its column"
        page.eval_on_selector("#side", "s => s.scrollTop = 0")
        screenshot(page, "modes_twelve")
        assert not errors, errors
    finally:
        runner.destroy()
