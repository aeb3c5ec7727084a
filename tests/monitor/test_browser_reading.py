"""The monitor page as a new user meets it, in headless Chromium (Debian's, through Playwright)
against the running simulated robot: the tree drawn to be read (labels at 11 px or more, deep
subtrees folded to fit, an overview where the tree is larger than the view, the running path
kept in view), maximising a panel, the blackboard's columns, the phone's toolbar, and saving
the tree as SVG and PNG with no Graphviz on the machine. Pages here open on the page's own
defaults (tests/monitor/browser.py's open_page chooses "Fit" instead). Screenshots go to
test-artifacts/monitor."""

from __future__ import annotations

import struct
import xml.etree.ElementTree as ElementTree
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from playwright.sync_api import Browser, Page

from tests.monitor.browser import Live, live_system, screenshot

pytestmark = pytest.mark.heavy

DESKTOP = {"width": 1400, "height": 900}
PHONE = {"width": 390, "height": 844}
READABLE_PX = 11.0

LABELS_ON_SCREEN = """() => {
  const view = document.getElementById('tree').getBoundingClientRect();
  const scale = document.getElementById('viewport').getCTM().a;
  return [...document.querySelectorAll('g.node text')].map((text) => {
    const box = text.getBoundingClientRect();
    const inside = box.width > 0 && box.left >= view.left && box.right <= view.right
      && box.top >= view.top && box.bottom <= view.bottom;
    return [text.textContent, parseFloat(getComputedStyle(text).fontSize) * scale, box.height,
            inside];
  });
}"""
"""Each label drawn: its text, the font size it is drawn at (CSS font size times the view's
zoom), its rendered height (0 when left out), and whether it is wholly inside the tree view."""

RUNNING_END_ON_SCREEN = """() => {
  const view = document.getElementById('tree').getBoundingClientRect();
  const active = [...document.querySelectorAll('g.node.active')];
  const edge = (from, to) => `path.edge[data-parent="${from}"][data-child="${to}"]`;
  const end = active.find((g) => !active.some((other) => other !== g
    && document.querySelector(edge(g.dataset.id, other.dataset.id))));
  if (!end) return null;
  const box = end.getBoundingClientRect();
  return box.left >= view.left && box.right <= view.right && box.top >= view.top
    && box.bottom <= view.bottom;
}"""
"""Whether the end of the running path (the active node with no active child drawn) is wholly
in the tree view; null while no path is drawn."""


PATH_OFF_SCREEN = """() => {
  const view = document.getElementById('tree').getBoundingClientRect();
  return [...document.querySelectorAll('g.node.active')].some((g) => {
    const box = g.getBoundingClientRect();
    return box.right < view.left || box.left > view.right || box.bottom < view.top
      || box.top > view.bottom;
  });
}"""
"""Whether a node of the running path is wholly outside the tree view."""


def _assert_path_bar(page: Page) -> None:
    """The path bar is shown exactly while part of the running path is off-screen; its first
    name brings the root into view."""
    bar = page.locator("#tree-path")
    page.wait_for_function(f"({PATH_OFF_SCREEN})() === !document.getElementById('tree-path')"
                           ".hidden")
    if bar.is_hidden():
        return
    names = bar.locator("button").all_text_contents()
    assert len(names) == page.locator("g.node.active").count()
    bar.locator("button").first.click()
    root = page.locator("g.node.active").first
    page.wait_for_function("(() => { const view = document.getElementById('tree')"
                           ".getBoundingClientRect(); const box = document.querySelector("
                           "'g.node.active').getBoundingClientRect(); return box.left >= view.left"
                           " && box.right <= view.right && box.top >= view.top; })()")
    assert root.text_content() == names[0]


@pytest.fixture(scope="module")
def live() -> Iterator[Live]:
    with live_system() as running:
        yield running


@pytest.fixture(autouse=True)
def _close_pages(browser: Browser) -> Iterator[None]:
    """Each test's pages are closed after it: live pages left open would share the machine."""
    yield
    for context in browser.contexts:
        context.close()


def _page(browser: Browser, live: Live, viewport: dict[str, int],
          errors: list[str]) -> Page:
    page = browser.new_page(viewport=viewport, accept_downloads=True)  # type: ignore[arg-type]
    page.on("console", lambda message: errors.append(message.text)
            if message.type == "error" else None)
    page.on("pageerror", lambda error: errors.append(str(error)))
    page.goto(live.url)
    page.wait_for_function("window.__monitor && window.__monitor.frames > 3", timeout=30000)
    return page


def _assert_readable(page: Page, least: int) -> list[Any]:
    page.wait_for_function(f"({RUNNING_END_ON_SCREEN})() === true", timeout=15000)
    labels: list[Any] = page.evaluate(LABELS_ON_SCREEN)
    small = [label for label in labels if label[1] < READABLE_PX or label[2] < READABLE_PX]
    assert small == [], f"labels drawn under {READABLE_PX} px: {small}"
    in_view = [label for label in labels if label[3]]
    assert len(in_view) >= least, f"at least {least} labels in view: {labels}"
    return labels


def test_the_tree_is_drawn_readable_on_a_desktop_and_on_a_phone(browser: Browser,
                                                                 live: Live) -> None:
    errors: list[str] = []
    page = _page(browser, live, DESKTOP, errors)
    _assert_readable(page, 2)
    assert not page.is_checked("#autofit"), "fitting is for the user to ask"
    assert page.locator("g.node.folded").count() >= 1, "what does not fit is folded"
    assert page.locator("#tree-overview").is_visible(), "an overview of a tree wider than the view"
    screenshot(page, "readable_1400x900")
    phone = _page(browser, live, PHONE, errors)
    phone.click("#tabs button[data-tab=tree]")
    _assert_readable(phone, 2)
    assert phone.locator("#tree-overview").is_visible()
    screenshot(phone, "readable_phone_tree")
    _assert_path_bar(phone)
    # "Fold" off: every node drawn, at the readable size all the same
    page.uncheck("#foldfit")
    nodes = len(list(live.system.runner.tree))
    page.wait_for_function(f"window.__monitor.drawn === {nodes}")
    _assert_readable(page, 2)
    # "Fit all" on request (every node drawn: a layout that stays): the whole tree, smaller,
    # kept when the window is resized; "1:1" goes back to the readable size
    page.click("#fit")
    inside = page.evaluate("""() => {
      const view = document.getElementById('tree').getBoundingClientRect();
      return [...document.querySelectorAll('g.node rect')].filter((rect) => {
        const box = rect.getBoundingClientRect();
        return box.left >= view.left - 1 && box.right <= view.right + 1;
      }).length;
    }""")
    assert inside == nodes
    assert page.evaluate("document.getElementById('viewport').getCTM().a") < 1
    width = page.evaluate("document.getElementById('tree').clientWidth")
    page.set_viewport_size({"width": 1300, "height": 900})
    page.wait_for_function(f"document.getElementById('tree').clientWidth !== {width}")
    page.evaluate("new Promise((done) => requestAnimationFrame(() => requestAnimationFrame(done)))")
    assert page.evaluate("document.getElementById('viewport').getCTM().a") < 1
    page.click("#readable")
    _assert_readable(page, 2)
    assert errors == []


def test_the_running_path_comes_back_into_view_once_the_user_stops_panning(
        browser: Browser, live: Live) -> None:
    errors: list[str] = []
    page = _page(browser, live, DESKTOP, errors)
    page.wait_for_function(f"({RUNNING_END_ON_SCREEN})() === true", timeout=15000)
    view = page.locator("#tree").bounding_box()
    assert view is not None
    page.mouse.move(view["x"] + 20, view["y"] + view["height"] - 60)
    page.mouse.down()
    page.mouse.move(view["x"] + 20, view["y"] - 2000, steps=4)  # the tree dragged far up
    page.mouse.up()
    assert page.evaluate(f"({RUNNING_END_ON_SCREEN})()") is False
    # once the user has stopped panning, the next move of the running path is shown
    page.wait_for_function(f"({RUNNING_END_ON_SCREEN})() === true", timeout=40000)
    assert errors == []


def test_maximise_gives_the_panel_the_page_and_survives_a_reload(browser: Browser,
                                                                 live: Live) -> None:
    errors: list[str] = []
    page = _page(browser, live, DESKTOP, errors)
    page.wait_for_function("!document.getElementById('map-view').classList.contains('empty')",
                           timeout=20000)
    for panel in ("view", "map-view"):
        page.click(f"#{panel} button.maximise")
        page.wait_for_function(f"document.getElementById('{panel}').getBoundingClientRect()"
                               f".width >= {DESKTOP['width'] - 1}")
        assert page.locator("#side").is_hidden(), "the details make room too"
        screenshot(page, f"maximised_{panel}")
        page.reload()
        page.wait_for_function("window.__monitor && window.__monitor.frames > 3")
        page.wait_for_function(f"document.getElementById('{panel}').getBoundingClientRect()"
                               f".width >= {DESKTOP['width'] - 1}", timeout=20000)
        page.click(f"#{panel} button.maximise")
        page.wait_for_function("document.getElementById('side').getBoundingClientRect()"
                               ".right >= window.innerWidth - 1")
        assert page.locator("#view").is_visible() and page.locator("#map-view").is_visible()
    assert errors == []


def test_blackboard_keys_show_whole_and_long_values_are_cut_with_the_whole_on_hover_and_click(
        browser: Browser, live: Live) -> None:
    report = {"goals": ["Lecture hall", "Library", "Courtyard", "Cafeteria", "Workshop"],
              "people_met": 3, "note": "a value far longer than the panel is wide"}
    live.system.runner.tree.blackboard.set("patrol_report", report)
    errors: list[str] = []
    page = _page(browser, live, DESKTOP, errors)
    page.wait_for_function("[...document.querySelectorAll('#bb-rows tr')].some("
                           "(tr) => tr.cells[1].textContent === 'patrol_report')",
                           timeout=20000)
    keys = page.evaluate("""() => [...document.querySelectorAll('#bb-rows tr')].map((tr) => {
      const cell = tr.cells[1], text = document.createRange();
      text.selectNodeContents(document.createTreeWalker(cell, NodeFilter.SHOW_TEXT).nextNode());
      const lines = new Set([...text.getClientRects()].map((box) => Math.round(box.top)));
      return [cell.textContent, cell.clientWidth, text.getBoundingClientRect().width, lines.size];
    })""")
    assert keys
    for key, width, text_width, lines in keys:
        if len(key) <= 20:
            assert lines == 1 and text_width <= width, f"key {key!r} wrapped or cut in {width} px"
    row = "[...document.querySelectorAll('#bb-rows tr')].find((tr) => " \
              "tr.cells[1].textContent === 'patrol_report')"
    value = page.evaluate(f"""() => {{ const cell = {row}.cells[2];
      return [cell.textContent, cell.title, cell.scrollWidth > cell.clientWidth,
              cell.getBoundingClientRect().height]; }}""")
    text, title, cut, height = value
    assert text.startswith("{") and title == text, "the whole value on hover"
    assert cut, "a long value is cut to one line"
    page.evaluate(f"{row}.cells[2].click()")
    page.wait_for_function(f"{row}.classList.contains('open')")
    page.wait_for_function(f"(() => {{ const cell = {row}.cells[2];"
                           f" return cell.scrollWidth <= cell.clientWidth"
                           f" && cell.getBoundingClientRect().height > {height}; }})()")
    screenshot(page, "blackboard")
    assert errors == []


def test_the_phone_toolbar_fits_390_px_with_save_and_the_seat_in_reach(browser: Browser,
                                                                       live: Live) -> None:
    errors: list[str] = []
    page = _page(browser, live, PHONE, errors)
    fits = "(() => { const bar = document.getElementById('toolbar');" \
           " return bar.scrollWidth <= bar.clientWidth && bar.getBoundingClientRect().right" \
           " <= 390 && document.documentElement.scrollWidth <= 390; })()"
    assert page.evaluate(fits), "the toolbar is no wider than the phone"
    for element in ("#seat", "#run", "#toolbar-menu"):
        box = page.locator(element).bounding_box()
        assert box is not None and box["x"] >= 0 and box["x"] + box["width"] <= 390, element
    page.click("#toolbar-menu")
    for kind in ("dot", "svg", "png"):
        button = page.locator(f"button[data-export={kind}]")
        box = button.bounding_box()
        assert button.is_visible() and box is not None and box["x"] + box["width"] <= 390
    assert page.evaluate(fits), "the opened menu wraps within the width too"
    screenshot(page, "phone_toolbar_open")
    with page.expect_download() as download:
        page.click("button[data-export=svg]")
    assert download.value.suggested_filename.endswith(".svg")
    assert errors == []


def _png_size(data: bytes) -> tuple[int, int]:
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    width, height = struct.unpack(">II", data[16:24])
    return width, height


def test_svg_and_png_are_saved_from_the_page_without_graphviz(
        browser: Browser, live: Live, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("PATH", str(tmp_path))  # no `dot` to be found
    errors: list[str] = []
    page = _page(browser, live, DESKTOP, errors)
    page.wait_for_function(f"({RUNNING_END_ON_SCREEN})() === true", timeout=15000)
    labels = set(page.locator("g.node text").all_text_contents())
    saved = {}
    names = []
    for kind in ("dot", "svg", "png"):
        with page.expect_download() as download:
            page.click(f"button[data-export={kind}]")
        names.append(download.value.suggested_filename)
        saved[kind] = Path(download.value.path()).read_bytes()
    stem = names[0].removesuffix(".dot")
    assert names == [f"{stem}.dot", f"{stem}.svg", f"{stem}.png"], "named as the server names DOT"
    svg = ElementTree.fromstring(saved["svg"])
    namespace = "{http://www.w3.org/2000/svg}"
    assert svg.tag == f"{namespace}svg"
    texts = {text.text for text in svg.iter(f"{namespace}text")}
    assert labels <= texts, "what is shown is saved, folded nodes folded"
    rects = [rect for rect in svg.iter(f"{namespace}rect") if "fill:" in rect.get("style", "")]
    assert rects and all("stroke:" in rect.get("style", "") for rect in rects), \
        "each box carries its look (the file stands alone)"
    width, height = _png_size(saved["png"])
    assert width == pytest.approx(2 * float(svg.get("width", "0")), abs=2)
    assert height == pytest.approx(2 * float(svg.get("height", "0")), abs=2)
    assert saved["dot"].startswith(b"digraph"), "DOT is text: no Graphviz needed either"
    assert errors == []
