"""Attacks on the monitor from a real browser (Debian's Chromium, driven by Playwright): a page
whose name is rebound to 127.0.0.1 (Chromium's own resolver rules stand in for the attacker's
DNS) and a page of another site on this machine. Neither may reach, let alone control, the robot.
Everything stays on loopback."""

from __future__ import annotations

import shutil
from collections.abc import Iterator
from typing import Any

import pytest
from playwright.sync_api import Browser, Route, sync_playwright

from tests.monitor.browser import Live, live_system

pytestmark = pytest.mark.heavy

REBOUND = "rebind.attacker.example"
ATTACK = """async (url) => {
    const socket = new WebSocket(url);
    return await new Promise((resolve) => {
        let opened = false;
        socket.onopen = () => {
            opened = true;
            socket.send(JSON.stringify({t: "claim", req: 1}));
            socket.send(JSON.stringify({t: "enable", on: false, req: 2}));
        };
        socket.onmessage = (event) => {
            const message = JSON.parse(event.data);
            if (message.t === "result" && message.req === 2) resolve({opened, result: message});
        };
        socket.onclose = (event) => resolve({opened, code: event.code});
        setTimeout(() => resolve({opened, timeout: true}), 5000);
    });
}"""


@pytest.fixture(scope="module")
def browser() -> Iterator[Browser]:
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    assert chromium, "Debian's chromium must be installed (scripts/test.sh installs it)"
    with sync_playwright() as playwright:
        launched = playwright.chromium.launch(
            executable_path=chromium,
            args=["--disable-gpu", "--disable-quic",
                  f"--host-resolver-rules=MAP {REBOUND} 127.0.0.1"])
        yield launched
        launched.close()


@pytest.fixture
def live() -> Iterator[Live]:
    with live_system() as running:
        yield running


def _attacker_page(browser: Browser, url: str) -> Any:
    """A page of the attacker's site at ``url`` (served by the test, not the network)."""
    page = browser.new_page()

    def serve(route: Route) -> None:
        route.fulfill(status=200, content_type="text/html",
                      body="<!doctype html><title>cute cats</title><link rel=icon href=data:,>")

    page.route(url, serve)
    page.goto(url)
    return page


def test_a_rebound_name_gets_403_and_its_page_cannot_control(browser: Browser,
                                                             live: Live) -> None:
    port = live.monitor.port
    page = browser.new_page()
    response = page.goto(f"http://{REBOUND}:{port}/")
    assert response is not None and response.status == 403
    assert f"--allow-host {REBOUND}" in page.content()
    # the attacker's page, already loaded from its own server, after the name was rebound
    attacker = _attacker_page(browser, f"http://{REBOUND}:{port}/cats")
    outcome = attacker.evaluate(ATTACK, f"ws://{REBOUND}:{port}/ws")
    assert outcome["opened"] is False, outcome
    assert live.system.runner.enabled and live.monitor.hub.seat.holder is None


def test_a_page_of_another_site_on_this_machine_cannot_connect(browser: Browser,
                                                               live: Live) -> None:
    attacker = _attacker_page(browser, "http://attacker.example/")
    outcome = attacker.evaluate(ATTACK, f"ws://127.0.0.1:{live.monitor.port}/ws")
    assert outcome["opened"] is False, outcome
    assert live.system.runner.enabled and live.monitor.hub.seat.holder is None
