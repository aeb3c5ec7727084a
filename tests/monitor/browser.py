"""Helpers for the monitor's browser tests: Debian's Chromium driven by Playwright, a running
system with a monitor, screenshots kept as artifacts (``test-artifacts/monitor`` or
``$CYBORG_TEST_ARTIFACTS``)."""

from __future__ import annotations

import os
import shutil
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from playwright.sync_api import Browser, Page, Playwright

from cyborg.bus import Node
from cyborg.monitor import Monitor
from tests.running_system import System, running_system

ROOT = Path(__file__).resolve().parents[2]
CAMPUS_MAP = ROOT / "src/cyborg/app/data/campus.map"
CAMPUS_TREE = ROOT / "src/cyborg/app/data/campus_patrol.b3.json"
ARTIFACTS = Path(os.environ.get("CYBORG_TEST_ARTIFACTS", ROOT / "test-artifacts")) / "monitor"


def launch_chromium(playwright: Playwright) -> Browser:
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    assert chromium, "Debian's chromium must be installed (scripts/test.sh installs it)"
    return playwright.chromium.launch(executable_path=chromium,
                                      args=["--disable-gpu", "--disable-quic"])


def screenshot(page: Page, name: str) -> Path:
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    path = ARTIFACTS / f"{name}.png"
    page.screenshot(path=str(path))
    return path


@dataclass
class Live:
    system: System
    monitor: Monitor

    @property
    def url(self) -> str:
        return f"http://127.0.0.1:{self.monitor.port}/"


@contextmanager
def live_system(*, speed: float = 10.0, token: str | None = None, port: int = 0,
                simulator: bool = True) -> Iterator[Live]:
    """The campus system with a monitor on a free port, on every interface (without its
    simulator when not ``simulator``)."""
    with running_system(CAMPUS_MAP, CAMPUS_TREE, speed=speed, simulator=simulator) as system:
        monitor = Monitor(Node("monitor", "/cyborg", context=system.context),
                          namespaces=["/cyborg/bt"], host="0.0.0.0", port=port, token=token)
        monitor.start()
        try:
            yield Live(system, monitor)
        finally:
            monitor.stop()


WHOLE_TREE = ("localStorage.setItem('cyborg-monitor-fit', 'true');"
              " localStorage.setItem('cyborg-monitor-fold', 'false');")
"""A page script choosing the tree view's "Fit" and not "Fold": every node drawn, the whole
tree in view (the page's default is a readable size, folded to fit; tests of it open their own
pages)."""


def open_page(browser: Browser, url: str, errors: list[str]) -> Page:
    """A fresh page on ``url`` that records console errors into ``errors``; waits for ticks.
    The tree view shows the whole tree (:data:`WHOLE_TREE`), so that every node can be
    clicked."""
    page = browser.new_page(viewport={"width": 1400, "height": 820}, accept_downloads=True)
    page.add_init_script(WHOLE_TREE)
    page.on("console", lambda message: errors.append(message.text)
            if message.type == "error" else None)
    page.on("pageerror", lambda error: errors.append(str(error)))
    page.goto(url)
    page.wait_for_function("window.__monitor && window.__monitor.frames > 3", timeout=20000)
    return page


def active_on_page(page: Page) -> list[str]:
    ids: list[str] = page.eval_on_selector_all(
        "g.node.active", "nodes => nodes.map(n => n.dataset.id)")
    return ids
