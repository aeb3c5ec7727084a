"""The lines redrawn in place on a terminal: the tree's status line (`cyborg up`, `cyborg bt run`)
and the progress bars (`cyborg detect` on a video, `cyborg detect models fetch`)."""

from __future__ import annotations

import io
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from cyborg.app.progress import ProgressBar, Unit
from cyborg.app.status_line import StatusLine, fit_status
from cyborg.bt import Status, Tree, load_tree, loads_tree
from cyborg.bt.snapshot import TickSnapshot
from tests.builders import N, project_json, registry, tree_json
from tests.running_system import write_tree

CAMPUS = ["Campus mission", "Priority", "Patrol", "Repeat -1x", "MemSequence",
          "MoveTo Lecture hall"]


class Terminal(io.StringIO):
    """A stream that says it is a terminal, so lines are redrawn in place."""

    def isatty(self) -> bool:
        return True

    def drawn(self) -> list[str]:
        """The lines drawn, as a terminal shows them (each ``\\r`` starts over)."""
        return [part.replace("\x1b[K", "").rstrip("\n").rstrip()
                for part in self.getvalue().split("\r") if part.strip()]


# ---------------------------------------------------------------------------------- status line
def test_a_short_status_line_is_written_in_full() -> None:
    assert fit_status(42, Status.RUNNING, ["Root", "MoveTo room1"], 80) == \
        "tick     42  RUNNING  Root > MoveTo room1"
    assert fit_status(3, Status.SUCCESS, [], 80) == "tick      3  SUCCESS  -"


def test_the_status_line_of_a_mode_machine_names_the_mode_and_its_trees_nodes() -> None:
    patrol = loads_tree(project_json([tree_json(N("Sequence", N("Runner"), title="Go"),
                                                title="Patrol")]), registry=registry())
    charge = loads_tree(project_json([tree_json(N("Runner", title="Charge"), title="Go charge",
                                                tree_id="charge")]), registry=registry())
    modes = {id(patrol): "normal", id(charge): "low_battery"}
    made_by: dict[int, Tree] = {}

    def tick(tree: Tree) -> TickSnapshot:
        snapshot = tree.tick()
        made_by[id(snapshot)] = tree
        return snapshot

    stream = io.StringIO()
    line = StatusLine(patrol, stream, tree_of=lambda snapshot: made_by[id(snapshot)],
                      mode_of=lambda snapshot: modes[id(made_by[id(snapshot)])])
    line.update(tick(patrol))
    line.update(tick(charge))
    assert stream.getvalue().splitlines() == [
        "tick      1  RUNNING  [normal] Patrol > Go > Runner",
        "tick      1  RUNNING  [low_battery] Go charge > Charge"]


@pytest.mark.parametrize("width", [80, 40])
@pytest.mark.parametrize("tick", [7, 123_456, 98_765_432])
def test_the_status_line_fits_and_keeps_tick_and_status(width: int, tick: int) -> None:
    path = [*CAMPUS[:-1], "Patrol the whole east wing twice", *CAMPUS[-1:]]
    text = fit_status(tick, Status.RUNNING, path, width)
    assert len(text) <= width, text
    assert text.startswith(f"tick {tick:>6}  RUNNING"), text
    assert "…" in text, "the path was shortened, visibly"
    if width == 80:  # the root and the node running now are the parts kept
        assert text.startswith(f"tick {tick:>6}  RUNNING  Campus mission > …"), text
        assert text.endswith(" > MoveTo Lecture hall"), text


@given(tick=st.integers(0, 10**9), status=st.sampled_from(list(Status)),
       labels=st.lists(st.text(min_size=1, max_size=60), max_size=12),
       width=st.integers(24, 300))
def test_any_status_line_fits_any_width(tick: int, status: Status, labels: list[str],
                                        width: int) -> None:
    text = fit_status(tick, status, labels, width)
    assert len(text) <= width
    assert f"tick {tick}" in " ".join(text.split()) and status.name in text


def test_the_live_status_line_fits_the_terminal(tmp_path: Path,
                                                monkeypatch: pytest.MonkeyPatch) -> None:
    node: dict[str, object] = {"name": "Runner", "title": "Wait for the very long name"}
    for label in reversed(CAMPUS[1:-1]):
        node = {"name": "Sequence", "title": label, "composite": True, "children": [node]}
    tree = load_tree(write_tree(tmp_path, {"name": "Sequence", "title": CAMPUS[0],
                                           "composite": True, "children": [node]}))
    snapshot = tree.tick()
    drawn: dict[int, str] = {}
    for columns in (80, 40):
        monkeypatch.setenv("COLUMNS", str(columns))
        terminal = Terminal()
        StatusLine(tree, terminal).update(snapshot)
        (drawn[columns],) = terminal.drawn()
        assert len(drawn[columns]) < columns, drawn  # the last column is left free: no wrap
        assert drawn[columns].startswith("tick      1  RUNNING  "), drawn
    assert drawn[80] == ("tick      1  RUNNING  Test tree > … > MemSequence > "
                         "Wait for the very long name")  # the root is the tree's title
    assert drawn[40] == "tick      1  RUNNING  Wait for the ver…"


# ---------------------------------------------------------------------------------- progress
def test_a_download_bar_counts_bytes(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("COLUMNS", "80")
    bar = ProgressBar(io.StringIO(), 3_800_000, unit="bytes")
    bar.done = 1_234_567
    text = bar.text()
    assert "1.2/3.8 MB" in text and "B/s" in text, text
    assert "FPS" not in text and "frames" not in text and "bytes" not in text, text
    assert len(text) < 80
    bar.total = 900
    bar.done = 512
    assert "512/900 B" in bar.text()
    bar.total = 25_600
    bar.done = 2_048
    assert "2.0/25.6 kB" in bar.text()


def test_a_video_bar_counts_frames(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("COLUMNS", "80")
    bar = ProgressBar(io.StringIO(), 1500)
    bar.done = 45
    text = bar.text("3 objects")
    assert "45/1500 frames" in text and "FPS" in text and "3 objects" in text, text
    assert "B/s" not in text
    assert len(text) < 80
    assert text.startswith("[.") and "]  45/1500" in text, "a bar, 3 % filled"
    bar.done = 750
    assert "#" * 10 in bar.text(), "half filled"


@pytest.mark.parametrize("unit", ["bytes", "frames"])
@pytest.mark.parametrize("columns", [80, 40, 20])
def test_the_live_bar_fits_the_terminal(monkeypatch: pytest.MonkeyPatch, unit: Unit,
                                        columns: int) -> None:
    monkeypatch.setenv("COLUMNS", str(columns))
    terminal = Terminal()
    bar = ProgressBar(terminal, 987_654_321, unit=unit)
    bar.update(123_456_789, "17 objects in this frame")
    bar.finish("17 objects in this frame")
    lines = terminal.drawn()
    assert lines
    for line in lines:
        assert len(line) < columns, line
        assert line.split()[0].startswith(("[", "123")), "the count is what stays"


def test_a_bar_ends_its_line_only_when_it_drew_one() -> None:
    untouched = Terminal()
    ProgressBar(untouched, 3_800_000, unit="bytes").finish()  # a cached model: nothing fetched
    assert untouched.getvalue() == ""
    terminal = Terminal()
    bar = ProgressBar(terminal, 3_800_000, unit="bytes")
    bar.update(3_800_000)
    bar.finish()
    assert "[" + "#" * 39 in terminal.getvalue() and "3.8/3.8 MB" in terminal.getvalue()
    assert terminal.getvalue().endswith("\n"), "what is printed next starts on its own line"
