"""The report says which clock each figure is on, counts tracked objects as objects, and
explains the path states goals end in (a recording of a simulated run at 10x)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from cyborg.bus.msgs.builtin_interfaces.msg import Time
from cyborg.bus.msgs.cyborg_msgs.msg import TrackedObject, TrackedObjects
from cyborg.bus.msgs.geometry_msgs.msg import Point, Vector3
from cyborg.bus.msgs.rosgraph_msgs.msg import Clock
from cyborg.bus.msgs.std_msgs.msg import String
from cyborg.report.build import build_report, read
from cyborg.report.clocks import run_clock
from cyborg.report.goals import PATH_STATES
from cyborg.report.recording import Stamped
from tests.report.page_reader import Page, read_page
from tests.report.recordings import RecordingWriter, detections, goal, header, mission

PACE = 10.0
"""Simulated seconds per wall second in the recording."""


def _objects(*tracks: tuple[int, str]) -> TrackedObjects:
    return TrackedObjects(header=header(), objects=[TrackedObject(
        id=track, label=label, confidence=0.9, position=Point(x=1.0, y=1.0, z=0.0),
        velocity=Vector3(x=0.0, y=0.0, z=0.0), last_seen=Time(sec=0, nanosec=0), times_seen=3,
        distance=2.0, bearing=0.0) for track, label in tracks])


@pytest.fixture(scope="module")
def simulated(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Page]:
    """The known mission, plus: /clock at 100 Hz running 10x, a goal cancelled near its goal,
    and three people tracked at 10 Hz for two minutes (one of them lost and found again as a
    new track), with their detections."""
    path = tmp_path_factory.mktemp("clocks") / "sim.mcap"
    writer = RecordingWriter(path)
    mission(path, writer=writer)
    for step in range(14_001):  # 0 to 140 s of wall time
        wall = step / 100
        simulated = round(wall * PACE * 1e9)
        writer.add("/clock", Clock(clock=Time(sec=simulated // 1_000_000_000,
                                              nanosec=simulated % 1_000_000_000)), wall)
    writer.add("/cyborg/arnl_path_state", String(data="MOVING_TO_GOAL"), 125.0)
    writer.add("/cyborg/current_goal", goal("room4", 7.0, 1.2), 125.001)
    writer.add("/cyborg/arnl_path_state", String(data="ABORTED_PATHPLAN"), 129.0)
    for frame in range(1200):  # two minutes at 10 frames a second
        seconds = frame / 10
        third = 3 if seconds < 60 else 4  # lost in minute 0, found again as a new track
        writer.add("/cyborg/objects", _objects((1, "person"), (2, "person"),
                                               (third, "person")), seconds)
        writer.add("/cyborg/detector/detections", detections("person", "person", "person"),
                   seconds + 0.01)
    writer.close()
    return path, read_page(build_report(path))


def _cells(row: object) -> list[str]:
    return [cell.all_text() for cell in row.children]  # type: ignore[attr-defined]


def test_the_duration_is_given_on_the_wall_clock_and_in_simulated_time(
        simulated: tuple[Path, Page]) -> None:
    _, page = simulated
    rows = {_cells(row)[0]: _cells(row)[1] for row in page.one("table", "meta").children[-1]
            .children}
    assert rows["duration"] == ("2:20 wall clock (first to last message); 23:20 simulated time "
                                "(/clock), 10x the wall clock")


def test_a_goal_took_as_long_on_each_clock_as_each_clock_says(
        simulated: tuple[Path, Page]) -> None:
    _, page = simulated
    table = page.one("table", "goals")
    header = _cells(table.children[0].children[0])
    assert header == ["start (wall)", "end (wall)", "took (s, wall)", "took (s, simulated)",
                      "goal", "outcome", "path state", "left to go (m)"]
    rows = [_cells(row) for row in table.children[1].children]
    assert rows[1][:6] == ["0:35", "0:55", "20.0", "200.0", "room2", "failed"]
    assert rows[-1] == ["2:05", "2:09", "4.0", "40.0", "room4", "cancelled",
                        "ABORTED_PATHPLAN", "0.1"]  # cancelled where MoveTo stops the robot


def test_the_tree_and_the_warnings_name_the_clock_of_their_times(
        simulated: tuple[Path, Page]) -> None:
    _, page = simulated
    header = _cells(page.one("table", "tree").children[0].children[0])
    assert header[-2:] == ["running time (s, tree clock)", "mean tick time (ms, wall)"]
    for table in page.find("table", "warnings"):
        assert _cells(table.children[0].children[0])[0] == "time (wall)"


def test_each_path_state_a_goal_ended_in_is_explained_in_plain_words(
        simulated: tuple[Path, Page]) -> None:
    _, page = simulated
    legend = {element.attrs["data-state"]: element.all_text()
              for element in page.find("dt", robot="robot-0") if "data-state" in element.attrs}
    assert legend == {"REACHED_GOAL": "REACHED_GOAL (3)", "FAILED_MOVE": "FAILED_MOVE (1)",
                      "ABORTED_PATHPLAN": "ABORTED_PATHPLAN (1)"}
    explained = [element.all_text() for element in page.find("dd", robot="robot-0")]
    assert PATH_STATES["ABORTED_PATHPLAN"] in explained
    assert "MoveTo stops the robot once it is within its radius" in (
        PATH_STATES["ABORTED_PATHPLAN"])
    cancelled = [cell for cell in page.find("td", "state", robot="robot-0")
                 if cell.all_text() == "ABORTED_PATHPLAN"]
    assert cancelled[0].attrs["title"] == PATH_STATES["ABORTED_PATHPLAN"]


def test_tracked_objects_count_each_person_once_and_detections_say_they_are_per_frame(
        simulated: tuple[Path, Page]) -> None:
    _, page = simulated
    tracked = page.one("table", "tracked", robot="robot-0")
    rows = {_cells(row)[0]: _cells(row)[1:] for row in tracked.children[1].children}
    assert _cells(tracked.children[0].children[0]) == ["minute", "person"]
    assert rows == {"0": ["3"], "1": ["3"], "all": ["4"]}  # person 3 was tracked again as 4
    detected = page.one("table", "detections", robot="robot-0")
    per_minute = {_cells(row)[0]: _cells(row)[1] for row in detected.children[1].children}
    assert (per_minute["0"], per_minute["1"]) == ("1802", "1801")  # 3 people x 600 frames,
    # and the known mission's own: two people in minute 0, one in minute 1
    titles = [element.attrs["aria-label"] for element in page.find("svg", "chart",
                                                                    robot="robot-0")]
    assert "objects tracked per minute (distinct track ids), by wall time since the recording "\
        "began" in titles
    assert "detections per minute (one per object per camera frame), by wall time since the "\
        "recording began" in titles


def test_only_a_sample_of_a_simulators_clock_is_decoded(simulated: tuple[Path, Page]) -> None:
    path, _ = simulated
    clock = read(path).stamped("/clock")
    assert 140 <= len(clock) <= 142  # one a wall second, and the last
    last = clock[-1].message.clock
    assert (int(last.sec), int(last.nanosec)) == (1400, 0)
    assert np.all(np.diff([item.log_time for item in clock]) > 0)


def _ticks(*pairs: tuple[float, float]) -> list[Stamped]:
    """``/clock`` messages: (wall seconds, simulated seconds) each."""
    return [Stamped(round(wall * 1e9), Clock(clock=Time(sec=int(simulated),
                                                        nanosec=round(simulated % 1 * 1e9))))
            for wall, simulated in pairs]


def test_a_clock_that_went_back_counts_from_its_restart() -> None:
    """A simulator restarted during the recording starts /clock again at 0: the report's
    simulated time is the last stretch that only rises."""
    run = run_clock(_ticks((0, 0), (1, 30), (2, 60), (3, 0), (4, 20), (5, 40)))
    assert run is not None
    assert (run.duration, run.pace, run.differs) == (40.0, 20.0, True)
    assert run.simulated_span(round(3.5e9), round(4.5e9)) == pytest.approx(20.0)


def test_too_little_clock_is_no_clock_and_the_same_pace_is_given_once() -> None:
    assert run_clock([]) is None
    assert run_clock(_ticks((0, 0))) is None
    assert run_clock(_ticks((0, 5), (1, 0))) is None  # went back at once: one message left
    same = run_clock(_ticks((0, 100), (10, 110.1)))
    assert same is not None and not same.differs  # 1 % off the wall clock's pace
