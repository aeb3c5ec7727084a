"""The monitor page in headless Chromium (Debian's, driven by Playwright) against the running
simulated robot: rendering, live active path, draw depth, exports, run/pause, per-node control
that changes what the robot does, restarts and reconnects, view-only access from the network.
Screenshots go to test-artifacts/monitor."""

from __future__ import annotations

import functools
import json
from collections.abc import Iterable, Iterator
from pathlib import Path

import pytest
from playwright.sync_api import Browser, Page

from cyborg.app.launchables import KINDS
from cyborg.bt.node import Node as BtNode
from cyborg.bt.status import FAILURE, RUNNING, Status
from cyborg.bus import Node
from cyborg.bus.component import NodeSpec
from cyborg.monitor import Monitor
from cyborg.monitor.monitor import _lan_address
from cyborg.runner.component import RunningTree
from cyborg.runner.tree_runner import TreeRunnerNode
from tests.monitor.browser import (
    CAMPUS_TREE,
    Live,
    active_on_page,
    live_system,
    open_page,
    screenshot,
)
from tests.running_system import wait_until

pytestmark = pytest.mark.heavy


@pytest.fixture
def live() -> Iterator[Live]:
    with live_system() as running:
        yield running


def _node(page: Page, label: str) -> str:
    """Click the node with this label; returns its id."""
    target = page.locator("g.node", has_text=label).first
    uid = target.get_attribute("data-id")
    assert uid is not None
    target.click()
    page.wait_for_function(f"document.getElementById('node-label').textContent === {label!r}")
    return uid


def _in_control(browser: Browser, live: Live, errors: list[str]) -> Page:
    page = open_page(browser, live.url, errors)
    _seat_says(page, "You have control")
    return page


def _seat_says(page: Page, text: str) -> None:
    _wait_page(page, f"document.getElementById('seat').textContent === {text!r}")


def _draw_depth(page: Page, depth: int) -> None:
    page.fill("#depth", str(depth))
    page.dispatch_event("#depth", "change")


def _wait_page(page: Page, script: str, timeout: float = 15000) -> None:
    page.wait_for_function(script, timeout=timeout)


def test_renders_the_sample_trees_one_robot_each(browser: Browser, live: Live,
                                                 shared: Path) -> None:
    context = live.system.context
    extra = []
    for name in ("patrol_recharge.b3.json", "stock_nodes.tree.json"):
        namespace = f"/samples/{name.split('.')[0]}/bt"
        node = Node("tree_runner", namespace, context=context)
        runner = TreeRunnerNode(node, shared / "trees" / name)
        runner.start()
        extra.append((namespace, runner))
    errors: list[str] = []
    try:
        page = open_page(browser, live.url, errors)
        assert page.locator("g.node").count() == 22
        screenshot(page, "campus")
        for namespace, runner in extra:
            _wait_page(page, f"[...document.querySelectorAll('#robot option')].some("
                             f"o => o.value === {namespace!r})")
            _show_robot(page, namespace, runner.tree)
            screenshot(page, namespace.strip("/").replace("/", "_"))
        assert page.locator("#robot option").count() == 3, "several robots from one page"
        # back to robots the page has shown before: their trees are drawn and follow again
        _show_robot(page, "/cyborg/bt", live.system.runner.tree)
        _show_robot(page, extra[0][0], extra[0][1].tree)
        assert errors == []
    finally:
        for _namespace, runner in extra:
            runner.destroy()


def _show_robot(page: Page, namespace: str, tree: Iterable[BtNode]) -> None:
    """Pick ``namespace`` in the robot list; wait until its whole tree is drawn and ticks of
    that tree arrive."""
    nodes = list(tree)
    page.select_option("#robot", namespace)
    _wait_page(page, f"window.__monitor.drawn === {len(nodes)}")
    assert page.locator("g.node").count() == len(nodes)
    labels = set(page.locator("g.node text").all_text_contents())
    assert {node.label for node in nodes} <= labels | {node.label[:39] + "…" for node in nodes}
    left = page.evaluate("Object.fromEntries([...document.querySelectorAll('g.node')].map(g => "
                         "[g.dataset.id, g.transform.baseVal[0].matrix.e]))")
    for node in nodes:  # children laid out left to right in tick order
        xs = [left[child.uid] for child in node.children]
        assert xs == sorted(xs) and len(set(xs)) == len(xs), node.label
    frames = page.evaluate("window.__monitor.frames")
    _wait_page(page, f"window.__monitor.frames > {frames + 3}")


def test_the_active_path_follows_the_running_tree(browser: Browser, live: Live) -> None:
    errors: list[str] = []
    page = open_page(browser, live.url, errors)
    runner = live.system.runner

    def running() -> tuple[str, ...]:
        last = runner.tree.last
        return tuple(last.active) if last is not None else ()

    def shown_or_moved(path: tuple[str, ...]) -> bool:
        return sorted(active_on_page(page)) == sorted(path) or running() != path

    seen: set[tuple[str, ...]] = set()
    while len(seen) < 3:  # three different running paths as the robot patrols
        wanted = running()
        if wanted in seen or not wanted:
            continue
        try:
            wait_until(functools.partial(shown_or_moved, wanted), 5,
                       "the page to show the running path")
        except AssertionError as exc:
            raise AssertionError(f"page shows {active_on_page(page)}, tree runs {wanted}") from exc
        if running() == wanted and sorted(active_on_page(page)) == sorted(wanted):
            seen.add(wanted)
            edges = page.locator("path.edge.active").count()
            assert edges == len(wanted) - 1, "the edges between running nodes are marked"
    screenshot(page, "active_path")
    assert errors == []


def test_draw_depth_folding_fit_and_hover(browser: Browser, live: Live) -> None:
    errors: list[str] = []
    page = open_page(browser, live.url, errors)
    _draw_depth(page, 0)
    _wait_page(page, "window.__monitor.drawn < 22")
    folded = page.locator("g.node.folded")
    assert folded.count() >= 1
    runner = live.system.runner
    wait_until(lambda: runner.tree.last is not None and set(runner.tree.last.active) <=
               set(active_on_page(page)), 5, "the running path to stay drawn")
    drawn = page.evaluate("window.__monitor.drawn")
    screenshot(page, "depth_0")
    _draw_depth(page, -1)
    _wait_page(page, "window.__monitor.drawn === 22")
    assert drawn < 22
    page.locator("g.node", has_text="Recharge").first.dblclick()
    _wait_page(page, "window.__monitor.drawn < 22")
    assert page.locator("g.node.folded", has_text="Recharge ▸ +").count() == 1
    page.locator("g.node.folded", has_text="Recharge").dblclick()
    _wait_page(page, "window.__monitor.drawn === 22")
    page.locator("g.node", has_text="Patrol").first.hover()
    assert page.locator("path.edge.hl").count() >= 2, "hover highlights the connections"
    before = page.get_attribute("#viewport", "transform")
    page.mouse.move(300, 300)
    page.mouse.wheel(0, -400)
    assert page.get_attribute("#viewport", "transform") != before
    assert not page.is_checked("#autofit"), "zooming by hand turns auto-fit off"
    page.click("#fit")
    assert page.get_attribute("#viewport", "transform") == before, "Fit in view fits again"
    received = page.evaluate("window.__monitor.structures")
    page.evaluate("document.getElementById('nodes').replaceChildren()")
    page.click("#refresh")
    _wait_page(page, f"window.__monitor.laidOut > {received}")  # drawn from the one re-sent
    assert page.locator("g.node").count() == 22 == page.evaluate("window.__monitor.drawn")
    frames = page.evaluate("window.__monitor.frames")
    _wait_page(page, f"window.__monitor.frames > {frames + 3}")
    assert errors == []


def test_export_downloads_what_is_shown(browser: Browser, live: Live) -> None:
    errors: list[str] = []
    page = open_page(browser, live.url, errors)
    _draw_depth(page, 0)
    _wait_page(page, "window.__monitor.drawn < 22")
    contents = {}
    for kind in ("dot", "svg", "png"):
        with page.expect_download() as download:
            page.click(f"button[data-export={kind}]")
        path = download.value.path()
        assert download.value.suggested_filename == f"Campus_mission.{kind}"
        contents[kind] = Path(path).read_bytes()
    assert contents["dot"].startswith(b"digraph") and b"(+" in contents["dot"], \
        "the folded view is exported, not the whole tree"
    assert b"<svg" in contents["svg"]
    assert contents["png"][:8] == b"\x89PNG\r\n\x1a\n"
    assert errors == []


def test_pause_resume_and_disabling_a_subtree_change_what_the_robot_does(
        browser: Browser, live: Live) -> None:
    system = live.system
    errors: list[str] = []
    page = _in_control(browser, live, errors)
    wait_until(lambda: system.sim.base.speed > 0.2, 20, "the robot driving")
    page.click("#run")
    wait_until(lambda: not system.runner.enabled, 5, "the tree paused")
    wait_until(lambda: abs(system.sim.base.speed) < 0.01, 10, "the robot to stop")
    _wait_page(page, "document.getElementById('run').textContent.includes('Run')")
    screenshot(page, "paused")
    page.click("#run")
    wait_until(lambda: system.runner.enabled and system.sim.base.speed > 0.2, 20,
               "the robot driving again")
    patrol = _node(page, "Patrol")
    page.click("#inspector button[data-action=disable][data-status=failure]")
    wait_until(lambda: system.runner.tree.hooks.get(patrol) is not None, 5, "the hook")
    wait_until(lambda: abs(system.sim.base.speed) < 0.01, 10, "the robot to stop")
    _wait_page(page, f"document.querySelector('g.node[data-id=\"{patrol}\"]')"
                     ".classList.contains('hooked')")
    screenshot(page, "patrol_disabled")
    page.reload()
    _seat_says(page, "You have control")  # this tab's seat secret took the seat back
    assert system.runner.tree.hooks.get(patrol) is not None, "a reload keeps the page's hooks"
    _node(page, "Patrol")
    page.click("#inspector button[data-action=clear]")
    wait_until(lambda: system.sim.base.speed > 0.2, 20, "the robot patrolling again")
    _force_failure_and_clear(page, live, patrol)
    assert errors == []


def _force_failure_and_clear(page: Page, live: Live, uid: str) -> None:
    """Force the selected node ``uid`` to fail: the runner's tree sees that result and so
    does the page; Clear gives the node its own result back."""
    tree = live.system.runner.tree

    def returned() -> Status | None:
        last = tree.last
        return dict(last.visited).get(uid) if last is not None else None

    node = f"document.querySelector('g.node[data-id=\"{uid}\"]')"
    page.click("#inspector button[data-action=force][data-status=failure]")
    wait_until(lambda: (hook := tree.hooks.get(uid)) is not None and hook.mode == "force"
               and hook.status == FAILURE, 5, "the force hook")
    wait_until(lambda: returned() == FAILURE, 5, "the node's forced result in the tree")
    _wait_page(page, f"{node}.classList.contains('s{int(FAILURE)}')")
    _wait_page(page, "document.getElementById('node-hook').textContent"
                     ".startsWith('force → failure')")
    page.click("#inspector button[data-action=clear]")
    wait_until(lambda: tree.hooks.get(uid) is None, 5, "the hook cleared")
    wait_until(lambda: returned() == RUNNING, 10, "the node's own result again")
    _wait_page(page, f"{node}.classList.contains('s{int(RUNNING)}')")


def test_breakpoint_step_resume_blackboard_timing_search_and_history(
        browser: Browser, live: Live) -> None:
    system = live.system
    errors: list[str] = []
    page = _in_control(browser, live, errors)
    priority = _node(page, "Priority")
    _wait_page(page, "document.getElementById('node-timing').textContent.includes('mean')")
    page.click("#inspector button[data-action=breakpoint]")
    _wait_page(page, "!document.getElementById('paused').hidden")
    assert system.runner.tree.hooks.paused_at == priority
    assert page.inner_text("#paused-node") == "Priority"
    screenshot(page, "breakpoint")
    page.click("#step")
    wait_until(lambda: system.runner.tree.hooks.paused_at not in (None, priority), 5,
               "a step to the next node")
    page.click("#inspector button[data-action=clear]")
    page.click("#resume")
    _wait_page(page, "document.getElementById('paused').hidden")
    ticks = system.runner.tree.ticks
    wait_until(lambda: system.runner.tree.ticks > ticks + 3, 10, "ticking again")
    _wait_page(page, "document.querySelectorAll('#bb-rows tr').length > 0")
    _blackboard_follows_the_tree(page, system.runner)
    page.fill("#search", "MoveTo")
    moves = sum(1 for node in system.runner.tree if "MoveTo" in node.label)
    assert page.inner_text("#search-count") == f"{moves} found"
    assert page.locator("g.node.match").count() == moves
    page.press("#search", "Enter")
    assert page.inner_text("#node-label").startswith("MoveTo")
    page.click("#history")
    _wait_page(page, "!document.getElementById('scrub').disabled")
    newest = page.evaluate("window.__monitor.tick")
    page.fill("#scrub", "0")
    page.dispatch_event("#scrub", "input")
    oldest = int(page.inner_text("#scrub-info").split()[1])  # set at once by the slider
    assert oldest < newest, "scrubbing goes back to an older tick"
    # the view is redrawn on the next animation frame: wait for it to show that tick
    _wait_page(page, f"document.getElementById('tickinfo').textContent.includes('tick {oldest} ')")
    screenshot(page, "history")
    page.click("#live")
    assert page.is_disabled("#scrub")
    assert errors == []


def _blackboard_follows_the_tree(page: Page, runner: TreeRunnerNode) -> None:
    """The patrol's MemSequence keeps its running child on the blackboard: as the robot
    moves on, the table shows the new value (marked as changed)."""
    def in_tree() -> str | None:
        scopes = runner.tree.blackboard.as_dict()
        found = [values["running_child"] for values in scopes["nodes"].values()
                 if "running_child" in values]
        return json.dumps(found[0]) if len(found) == 1 else None

    def on_page() -> tuple[str, str] | None:
        found: list[str] | None = page.evaluate(
            "(() => { const row = [...document.querySelectorAll('#bb-rows tr')].find("
            "(tr) => tr.cells[1].textContent === 'running_child');"
            " return row ? [row.cells[2].textContent, row.className] : null; })()")
        return (found[0], found[1]) if found else None

    wait_until(lambda: on_page() is not None, 5, "the running child in the table")
    first = on_page()
    assert first is not None
    wait_until(lambda: (shown := on_page()) is not None and shown[0] != first[0]
               and shown == (in_tree(), "changed"), 60,
               f"the table to follow the running child on from {first[0]}")


def test_the_page_follows_a_restarted_runner_a_reload_and_a_dropped_connection(
        browser: Browser, live: Live, shared: Path) -> None:
    system = live.system
    errors: list[str] = []
    page = open_page(browser, live.url, errors)
    page.evaluate("window.__marker = 'same page'")
    running = next(item for item in system.launch.running if isinstance(item, RunningTree))
    running.stop()
    system.launch.running.remove(running)
    _wait_page(page, "document.getElementById('banner').textContent.includes('not running')")
    screenshot(page, "runner_gone")
    restarted = KINDS["tree_runner"](system.context, NodeSpec(
        "tree_runner", "tree_runner", "/cyborg/bt",
        {"tree_file": str(CAMPUS_TREE), "use_sim_time": True, "robot_namespace": "/cyborg"}))
    system.launch.running.append(restarted)
    _wait_page(page, "document.getElementById('banner').hidden")
    frames = page.evaluate("window.__monitor.frames")
    _wait_page(page, f"window.__monitor.frames > {frames + 5}")
    assert page.evaluate("window.__marker") == "same page", "followed without a reload"
    assert isinstance(restarted, RunningTree)
    other = restarted.runner.reload(shared / "trees" / "stock_nodes.tree.json")
    _wait_page(page, f"window.__monitor.drawn === {len(other)}")
    assert page.evaluate("window.__marker") == "same page", "a reloaded tree is drawn in place"
    screenshot(page, "reloaded")
    # the monitor itself goes away and comes back on the same port
    port = live.monitor.port
    live.monitor.stop()
    _wait_page(page, "document.getElementById('banner').textContent.includes('lost')")
    screenshot(page, "connection_lost")
    live.monitor = Monitor(Node("monitor", "/cyborg", context=system.context),
                           namespaces=["/cyborg/bt"], port=port)
    live.monitor.start()
    _wait_page(page, "document.getElementById('banner').hidden", timeout=20000)
    frames = page.evaluate("window.__monitor.frames")
    _wait_page(page, f"window.__monitor.frames > {frames + 5}")
    assert page.evaluate("window.__marker") == "same page"
    errors = [error for error in errors if "ERR_CONNECTION_REFUSED" not in error]
    assert errors == []


def test_view_only_from_another_address_unless_the_token_is_given(browser: Browser) -> None:
    address = _lan_address()
    assert address, "this machine needs a non-loopback address for this test"
    with live_system(token="s3cret") as live:
        remote = f"http://{address}:{live.monitor.port}/"
        errors: list[str] = []
        page = open_page(browser, remote, errors)
        _seat_says(page, "View only")
        assert page.is_disabled("#run") and page.is_hidden("#take")
        _node(page, "Patrol")
        assert page.is_disabled("#inspector button[data-action=disable][data-status=failure]")
        refused = page.evaluate("""() => new Promise((resolve) => {
            const socket = new WebSocket(`ws://${location.host}/ws`);
            socket.onopen = () => socket.send(JSON.stringify({t: "enable", on: false, req: 1}));
            socket.onmessage = (event) => {
                const message = JSON.parse(event.data);
                if (message.t === "result") resolve(message);
            };
        })""")
        assert refused["ok"] is False and "view only" in refused["message"]
        assert live.system.runner.enabled
        screenshot(page, "view_only")
        page.close()
        trusted = open_page(browser, remote + "?token=s3cret", errors)
        _seat_says(trusted, "You have control")
        assert not trusted.is_disabled("#run")
        assert "token" not in trusted.url, "the token left the address bar (and history)"
        assert errors == [], json.dumps(errors)
