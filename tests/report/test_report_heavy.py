"""The report as a user meets it: opened from a file in Chromium, and made of a real run."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
from playwright.sync_api import Browser

from cyborg.report.build import build_report
from tests.ports import free_port
from tests.report.page_reader import polyline_points, read_page
from tests.report.recordings import mission

pytestmark = pytest.mark.heavy


def test_the_page_opens_from_its_file_without_errors_or_requests(
        browser: Browser, tmp_path: Path) -> None:
    path = tmp_path / "run.mcap"
    mission(path)
    assert subprocess.run([sys.executable, "-m", "cyborg", "report", str(path)],
                          capture_output=True, timeout=120).returncode == 0
    page = browser.new_page(viewport={"width": 1100, "height": 800})
    errors: list[str] = []
    requests: list[str] = []
    page.on("console", lambda message: errors.append(message.text)
            if message.type == "error" else None)
    page.on("pageerror", lambda error: errors.append(str(error)))
    page.on("request", lambda request: requests.append(request.url))
    page.goto((tmp_path / "run.html").as_uri())
    page.wait_for_load_state("load")
    headings = page.eval_on_selector_all("section.robot h3", "hs => hs.map(h => h.textContent)")
    assert headings == ["Tree", "Path driven", "Battery", "Goals", "Detections", "Warnings"]
    for selector in ("svg.map polyline.trajectory", "svg.chart polyline.charge",
                     "table.goals", "table.tree"):
        box = page.locator(selector).first.bounding_box()
        assert box is not None and box["width"] > 100, selector
    sequence = page.locator("table.tree tr[data-node='s'] td.label")
    sequence.click()  # folds its children
    assert page.locator("table.tree tr[data-node='a']").is_hidden()
    sequence.click()
    assert page.locator("table.tree tr[data-node='a']").is_visible()
    page.locator("svg.map").hover()
    assert (page.locator("p.pointer").text_content() or "").startswith("x ")
    assert errors == []
    assert requests == [(tmp_path / "run.html").as_uri()]
    page.close()


def test_a_recorded_cyborg_up_run_shows_the_trajectory_and_a_goal(tmp_path: Path) -> None:
    path = tmp_path / "up.mcap"
    result = subprocess.run(
        [sys.executable, "-m", "cyborg", "up", "--no-detector", "--no-monitor", "--record",
         str(path), "--duration", "15", "--listen", f"tcp/127.0.0.1:{free_port()}"],
        capture_output=True, text=True, timeout=180)
    assert result.returncode == 0, result.stderr
    report = tmp_path / "up.html"
    result = subprocess.run([sys.executable, "-m", "cyborg", "report", str(path), "-o",
                             str(report)], capture_output=True, text=True, timeout=180)
    assert result.returncode == 0, result.stderr
    page = read_page(report.read_text())
    assert [element.children[0].all_text() for element in page.find("section", "robot")] == \
        ["robot /cyborg"]
    assert len(polyline_points(page.one("polyline", "trajectory", robot="robot-0"))) > 10
    goals = [row for row in page.find("tr", robot="robot-0") if "data-outcome" in row.attrs]
    assert goals, page.section_text("goals", "robot-0")
    assert "campus.map" in page.one("table", "meta").all_text()
    nodes = [row for row in page.find("tr", robot="robot-0") if "data-node" in row.attrs]
    assert len(nodes) > 5 and int(nodes[0].attrs["data-running"]) > 0
    assert int(page.one("polyline", "charge").attrs["data-points"]) > 5


def test_the_page_fits_a_phone_390_px_wide(browser: Browser, tmp_path: Path) -> None:
    """At 390 x 844 (a phone) nothing makes the page scroll sideways: wide tables scroll inside
    their own box, charts and the map shrink, long names wrap."""
    path = tmp_path / "run.mcap"
    mission(path)
    (tmp_path / "run.html").write_text(build_report(path), encoding="utf-8")
    page = browser.new_page(viewport={"width": 390, "height": 844})
    page.goto((tmp_path / "run.html").as_uri())
    page.wait_for_load_state("load")
    widths = page.evaluate("() => [document.documentElement.scrollWidth, "
                           "document.body.scrollWidth, window.innerWidth]")
    assert widths[0] <= 390 and widths[1] <= 390 and widths[2] == 390, widths
    for selector in ("svg.map", "svg.chart", ".scroll:has(table.goals)",
                     ".scroll:has(table.tree)", "table.meta", "nav"):
        box = page.locator(selector).first.bounding_box()
        assert box is not None and box["x"] >= 0 and box["x"] + box["width"] <= 390 + 0.5, (
            selector, box)
    page.close()
