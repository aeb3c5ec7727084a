"""The services on composites in the page, in headless Chromium: a runner ticks a tree whose
Sequence carries a 0.1 s service; the Sequence wears a badge (a gear and the number of its
services, lit while one runs), and its details panel lists the service with its last run and
the key it wrote, updating as it runs; a service that raises shows its error in red.
Screenshots go to test-artifacts/monitor."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest
from playwright.sync_api import Browser, Page

from cyborg.bus import BusConfig, Context, Node
from cyborg.monitor import Monitor
from cyborg.runner.tree_runner import TreeRunnerNode
from tests.monitor.browser import open_page, screenshot
from tests.running_system import write_tree
from tests.service_trees import registry, sequence_of, sequence_with

pytestmark = pytest.mark.heavy


@pytest.fixture
def served(tmp_path: Path) -> Iterator[tuple[str, TreeRunnerNode]]:
    """The monitor's address, and the runner of a Sequence carrying Counter and Broken."""
    tree = write_tree(tmp_path, sequence_with("Counter(interval=0.1); Broken(interval=0.5)"))
    with Context(BusConfig.isolated()) as context:
        runner = TreeRunnerNode(Node("tree_runner", "/cyborg/bt", context=context), tree,
                                services=registry(), rate_hz=10.0)
        monitor = Monitor(Node("monitor", "/cyborg", context=context),
                          namespaces=["/cyborg/bt"], host="127.0.0.1", port=0)
        runner.start()
        monitor.start()
        try:
            yield monitor.urls()[0], runner
        finally:
            monitor.stop()
            runner.destroy()


def _wrote_count(page: Page) -> int:
    """What the panel says Counter wrote under ``count``."""
    text = page.locator("#node-services [data-service=Counter] tr",
                        has_text="wrote count").locator("td").nth(1).text_content()
    return int(text or "-1")


def test_the_badge_and_the_details_panel_show_the_services_as_they_run(
        browser: Browser, served: tuple[str, TreeRunnerNode]) -> None:
    url, runner = served
    errors: list[str] = []
    page = open_page(browser, url, errors)
    sequence = sequence_of(runner)
    node = page.locator(f'g.node[data-id="{sequence}"]')
    badge = node.locator("g.svc")
    assert badge.locator("text").text_content() == "⚙2", "a gear and the number of services"
    assert badge.locator("title").text_content() == \
        "services: Counter(interval=0.1); Broken(interval=0.5)"
    page.wait_for_function(
        f"document.querySelector('g.node[data-id=\"{sequence}\"] g.svc')"
        ".classList.contains('on')", timeout=20000)
    assert page.locator("g.svc").count() == 1, "only the composite with services has a badge"
    node.locator("rect").first.click()
    panel = page.locator("#node-services")
    panel.locator("[data-service=Counter]", has_text="wrote count").wait_for(timeout=20000)
    counter = panel.locator("[data-service=Counter]")
    assert "Counter(interval=0.1)" in (counter.text_content() or "")
    assert "running" in (counter.text_content() or "")
    first = _wrote_count(page)
    page.wait_for_function(
        "([before]) => { const row = [...document.querySelectorAll("
        "'#node-services [data-service=Counter] tr')].find(r => r.textContent.startsWith("
        "'wrote count')); return row && Number(row.cells[1].textContent) > before + 3; }",
        arg=[first], timeout=20000)
    last_ran = counter.locator("tr", has_text="last ran").text_content() or ""
    assert "t = " in last_ran and (" ago" in last_ran or "just now" in last_ran), last_ran
    broken = panel.locator("[data-service=Broken]")
    broken.locator(".svc-error").wait_for(timeout=20000)
    assert broken.locator(".svc-error").text_content() == \
        "RuntimeError: the sensor is unplugged"
    assert "stopped" in (broken.text_content() or "")
    screenshot(page, "services")
    # the tree disabled: every service stops, and the badge goes dark
    runner.set_enabled(False, wait=5.0)
    page.wait_for_function(
        f"!document.querySelector('g.node[data-id=\"{sequence}\"] g.svc')"
        ".classList.contains('on')", timeout=20000)
    counter.locator("tr", has_text="stopped").wait_for(timeout=20000)
    assert errors == []
