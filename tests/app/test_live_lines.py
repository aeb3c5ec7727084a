"""The lines redrawn in place on a terminal: the tree's status line (`cyborg up`, `cyborg bt run`)
and the progress bars (`cyborg detect` on a video, `cyborg detect models fetch`)."""

from __future__ import annotations

import io
import logging
import sys
import threading
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from cyborg.app.progress import LiveLine, ProgressBar, Unit
from cyborg.app.rate_window import FallingBehind, PaceWindow
from cyborg.app.status_line import StatusLine, fit_status
from cyborg.app.terminal import FLEET_WIDE, NamesRobot
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


# ------------------------------------------------------------- the terminal the line shares
class Screen(Terminal):
    """A terminal that keeps its rows as a screen shows them: ``\\r`` goes back to the row's
    start, ``ESC [ K`` wipes the rest of it, ``\\n`` starts a new row, text overwrites."""

    def rows(self) -> list[str]:
        rows: list[str] = [""]
        row: list[str] = []
        column = 0
        text = self.getvalue()
        index = 0
        while index < len(text):
            if text.startswith("\x1b[K", index):
                del row[column:]
                index += 3
                continue
            char = text[index]
            index += 1
            if char == "\r":
                column = 0
            elif char == "\n":
                rows[-1] = "".join(row)
                rows.append("")
                row, column = [], 0
            else:
                row[column:column + 1] = [char]
                column += 1
        rows[-1] = "".join(row)
        return [line.rstrip() for line in rows if line.strip()]


def test_log_records_and_prints_start_on_a_row_of_their_own_below_which_the_line_is_redrawn(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("COLUMNS", "60")
    tree = load_tree(write_tree(tmp_path, {"name": "Runner", "title": "MoveTo room1"}))
    screen = Screen()
    root = logging.getLogger()
    handler = logging.StreamHandler(screen)  # stderr, on the same terminal
    handler.setFormatter(logging.Formatter("%(levelname)s %(name)s: %(message)s"))
    monkeypatch.setattr(root, "handlers", [handler])
    monkeypatch.setattr(sys, "stdout", screen)
    clock = iter(range(100))
    line = StatusLine(tree, screen, wall=lambda: float(next(clock)))
    line.attach()
    line.update(tree.tick())
    logging.getLogger("cyborg.robot").warning("MoveTo room1: the way is blocked")
    print("a node says", end="")  # a line in two writes, as print writes it
    print(" hello")
    line.update(tree.tick())
    line.finish()
    assert "tick      1  RUNNING  Test tree > MoveTo room1" in screen.getvalue()
    rows = screen.rows()  # the warning took the line's row; the line is drawn again below
    assert rows[0] == "WARNING cyborg.robot: MoveTo room1: the way is blocked", rows
    assert rows[1] == "a node says hello", rows
    assert rows[2] == "tick      2  RUNNING  Test tree > MoveTo room1", rows
    assert rows[3].startswith("done after 2 ticks"), rows
    for row in rows:
        assert not ("tick " in row and ("WARNING" in row or "hello" in row)), rows
    assert sys.stdout is screen and root.handlers == [handler], "put back when it ends"


def test_a_fleets_log_records_name_their_robot() -> None:
    stream = io.StringIO()
    handler = logging.StreamHandler(stream)
    handler.addFilter(NamesRobot(["/robot1", "/robot2", "/robot10"]))
    logger = logging.getLogger("test.fleet")
    logger.addHandler(handler)
    logger.propagate = False

    def log_from(thread_name: str, message: str) -> None:
        thread = threading.Thread(target=logger.warning, args=(message,), name=thread_name)
        thread.start()
        thread.join()

    try:
        log_from("cyborg-tree /robot2/bt/tree_runner", "MoveTo room1: stalled")
        log_from("/robot10/bt/tree_runner[cancel]", "cancel failed")
        log_from("cyborg-tree /robot1/bt/tree_runner", "/robot1 is docked")  # named already
        log_from("simulation", "a person walks")  # no robot's thread
        thread = threading.Thread(target=logger.warning, args=("the simulation runs at 7x",),
                                  kwargs={"extra": {FLEET_WIDE: True}},
                                  name="cyborg-tree /robot1/bt/tree_runner")
        thread.start()
        thread.join()
    finally:
        logger.removeHandler(handler)
    assert stream.getvalue().splitlines() == [
        "/robot2: MoveTo room1: stalled", "/robot10: cancel failed", "/robot1 is docked",
        "a person walks", "the simulation runs at 7x"]


# ------------------------------------------------------------------ the pace of simulated time
def test_the_pace_is_simulated_seconds_per_wall_second_over_the_window() -> None:
    wall = [0.0]
    pace = PaceWindow(lambda: wall[0], window=5.0)
    assert pace.pace() is None
    for step in range(21):  # 10 s at 30x, then 10 s at 7x
        wall[0] = step * 0.5
        pace.add(step * 0.5 * 30)
    assert pace.pace() == pytest.approx(30.0)
    for step in range(1, 21):
        wall[0] = 10 + step * 0.5
        pace.add(300 + step * 0.5 * 7)
    assert pace.pace() == pytest.approx(7.0)


def test_falling_behind_is_said_once_after_it_lasted_naming_the_load_and_what_to_do() -> None:
    wall = [0.0]
    behind = FallingBehind(30.0, lambda: wall[0], patience=10.0, load=lambda: (5.25, 2))
    said = []
    for step in range(60):
        wall[0] = step * 0.5
        pace = 29.0 if step < 4 else 7.1 if step < 40 else 6.0
        if step == 10:
            pace = 16.0  # above half the asked pace: the 10 s start again
        said.append(behind.check(pace))
    warnings = [(step, text) for step, text in enumerate(said) if text]
    assert len(warnings) == 1
    step, text = warnings[0]
    assert step == 31  # below half from step 11 on (wall 5.5 s), 10 s later
    assert "runs at " in text and "below half the 30x asked (--speed)" in text
    assert "the CPU is busy (load average 5.2 on 2 CPUs)" in text
    assert "--speed 7" in text and "--speed 0" in text
    assert FallingBehind(0.0, lambda: 0.0).check(0.5) is None, "as fast as possible: never"


def test_falling_behind_on_an_idle_machine_blames_the_simulation_not_the_cpu() -> None:
    wall = [0.0]
    behind = FallingBehind(30.0, lambda: wall[0], patience=1.0, load=lambda: (0.6, 2))
    said = []
    for step in range(10):
        wall[0] = step * 0.5
        said.append(behind.check(12.0))
    (text,) = [text for text in said if text]
    assert "CPU is busy" not in text, text
    assert "the simulation itself is the limit, not the CPU (load average 0.6 on 2 CPUs" in text
    assert "--speed 12" in text


def test_the_live_line_shows_the_pace_reached_and_warns_once_when_it_falls_behind(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
        caplog: pytest.LogCaptureFixture) -> None:
    monkeypatch.setenv("COLUMNS", "80")
    tree = load_tree(write_tree(tmp_path, {"name": "Runner", "title": "MoveTo room1"}))
    wall = [0.0]
    terminal = Screen()
    line = StatusLine(tree, terminal, speed=30.0, wall=lambda: wall[0])
    line.behind = FallingBehind(30.0, lambda: wall[0], load=lambda: (3.0, 2))
    snapshot = tree.tick()
    for step in range(300):  # 30 s of wall time at 7x
        wall[0] = step * 0.1
        snapshot.time = step * 0.1 * 7
        line.update(snapshot)
    rows = terminal.rows()
    assert "7.0x/30x" in rows[-1], rows[-1]
    warnings = [record for record in caplog.records if "runs at 7.0x" in record.getMessage()]
    assert len(warnings) == 1 and warnings[0].levelno == logging.WARNING


def test_record_and_plays_live_line_keeps_log_records_off_its_row(
        monkeypatch: pytest.MonkeyPatch) -> None:
    class Counting(LiveLine):
        count = 0

        def text(self) -> str:
            return f"playing  {self.count} msgs"

    screen = Screen()
    handler = logging.StreamHandler(screen)
    handler.setFormatter(logging.Formatter("%(levelname)s %(name)s: %(message)s"))
    monkeypatch.setattr(logging.getLogger(), "handlers", [handler])
    line = Counting(screen)
    line.update()
    logging.getLogger("cyborg.bus").warning("a subscriber is slow")
    line.count = 5
    line._drawn = -1.0  # due again
    line.update()
    line.clear()
    print("played 5 messages", file=screen)
    assert screen.rows() == ["WARNING cyborg.bus: a subscriber is slow", "played 5 messages"]
    assert "playing  5 msgs" in screen.getvalue()
    assert logging.getLogger().handlers == [handler], "put back when the line is cleared"
