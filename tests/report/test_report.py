"""The run report of a known recording: its figures equal what was recorded."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from cyborg.bus.msgs.cyborg_msgs.msg import BehaviorTree
from cyborg.bus.msgs.geometry_msgs.msg import Pose2D
from cyborg.bus.msgs.std_msgs.msg import String
from cyborg.report.build import build_report
from cyborg.report.map_svg import trajectory_points
from cyborg.report.svg import MAX_CHART_POINTS
from tests.report.page_reader import Page, polyline_points, read_page
from tests.report.recordings import (
    Mission,
    RecordingWriter,
    battery,
    goal,
    mission,
    structure,
    tick,
)


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> tuple[Mission, Page]:
    path = tmp_path_factory.mktemp("report") / "run.mcap"
    recorded = mission(path)
    return recorded, read_page(build_report(path))


def test_the_header_names_the_run_its_duration_and_every_topic(
        run: tuple[Mission, Page]) -> None:
    _, page = run
    meta = page.one("table", "meta").all_text()
    for expected in ("9.9", "cyborg up --record run.mcap", "/maps/small.map",
                     "/trees/patrol.json", "small.map on /cyborg/map_geometry", "2:20",
                     "128 on 11 topics"):
        assert expected in meta
    counts = {row.children[0].all_text(): int(row.children[2].all_text())
              for row in page.one("table", "topics").children[1].children}
    assert counts["/cyborg/pose"] == 60 and counts["/cyborg/bt/status"] == 20
    assert counts["/rosout"] == 2 and len(counts) == 11
    assert not page.find("p", "cut")


def test_goals_reached_and_failed_are_counted_with_their_times(
        run: tuple[Mission, Page]) -> None:
    recorded, page = run
    tally = page.one("p", "tally", robot="robot-0")
    assert int(tally.attrs["data-reached"]) == recorded.reached == 3
    assert int(tally.attrs["data-failed"]) == recorded.failed == 1
    rows = [[cell.all_text() for cell in row.children]
            for row in page.one("table", "goals").children[1].children]
    assert rows[1] == ["0:35", "0:55", "20.0", "room2", "failed", "FAILED_MOVE", "2.0"]
    header = [cell.all_text() for cell in page.one("table", "goals").children[0].children[0]
              .children]
    assert header == ["start (wall)", "end (wall)", "took (s, wall)", "goal", "outcome",
                      "path state", "left to go (m)"]  # no /clock: no simulated column
    assert [row[3] for row in rows] == ["room1", "room2", "room3", "dock"]


def test_each_node_has_its_status_counts_and_running_time(run: tuple[Mission, Page]) -> None:
    _, page = run
    rows = {row.attrs["data-node"]: row for row in page.find("tr", robot="robot-0")
            if "data-node" in row.attrs}
    assert list(rows) == ["r", "s", "a", "b"]
    counts = {uid: tuple(int(row.attrs[f"data-{name}"])
                         for name in ("success", "failure", "running", "error"))
              for uid, row in rows.items()}
    assert counts == {"r": (8, 2, 10, 0), "s": (8, 2, 10, 0), "a": (10, 0, 10, 0),
                      "b": (8, 2, 0, 0)}
    running_time = [cell.all_text() for cell in rows["a"].children][5]
    assert running_time == "10.0"  # ten ticks running, a second apart
    assert [cell.all_text() for cell in rows["b"].children][5] == "0.0"
    ticks = [p.attrs["data-ticks"] for p in page.find("p", robot="robot-0", section="tree")
             if "data-ticks" in p.attrs]
    assert ticks == ["20"]


def test_the_battery_chart_has_a_point_per_message_and_the_charging_period_shaded(
        run: tuple[Mission, Page]) -> None:
    recorded, page = run
    line = page.one("polyline", "charge", robot="robot-0")
    points = polyline_points(line)
    assert int(line.attrs["data-points"]) == len(points) == len(recorded.battery)
    heights = [y for _, y in points]  # SVG y grows downwards: the higher the charge, the less
    order = sorted(range(len(heights)), key=lambda index: heights[index])
    assert order == sorted(range(len(recorded.battery)),
                           key=lambda index: -recorded.battery[index])
    charging = page.find("rect", "charging", robot="robot-0")
    periods = [rect for rect in charging if "period" in rect.classes]
    assert len(periods) == 1 and "60-100 s" in periods[0].all_text()
    assert len([rect for rect in page.find("rect", "docked") if "period" in rect.classes]) == 1


def test_the_trajectory_is_drawn_on_the_map_from_the_poses(run: tuple[Mission, Page]) -> None:
    recorded, page = run
    line = page.one("polyline", "trajectory", robot="robot-0")
    drawn = polyline_points(line)
    expected = trajectory_points(recorded.poses)
    assert len(drawn) == int(line.attrs["data-points"]) == len(expected) == 60
    assert drawn == [(round(x, 2), round(-y, 2)) for x, y in expected]
    assert page.find("path", "walls", robot="robot-0")
    assert int(page.one("path", "points").attrs["data-cells"]) > 50
    assert [element.all_text() for element in page.find("g", "goal")] == ["room1"]
    outcomes = [element.attrs["class"] for element in page.find("circle", "attempt")]
    assert outcomes.count("attempt reached") == 3 and outcomes.count("attempt failed") == 1


def test_detections_are_counted_per_class_and_minute(run: tuple[Mission, Page]) -> None:
    _, page = run
    table = page.one("table", "detections", robot="robot-0")
    header = [cell.all_text() for cell in table.children[0].children[0].children]
    rows = {row.children[0].all_text(): [int(cell.all_text()) for cell in row.children[1:]]
            for row in table.children[1].children}
    assert header == ["minute", "person", "chair"]
    assert rows == {"0": [2, 1], "1": [1, 0], "2": [1, 2], "all": [4, 3]}
    assert "Detections, counted from /cyborg/detector/detections" in page.section_text(
        "detections", "robot-0")


def test_warnings_list_the_log_and_what_went_wrong(run: tuple[Mission, Page]) -> None:
    _, page = run
    robot_rows = [[cell.all_text() for cell in row.children]
                  for row in page.one("table", "warnings", robot="robot-0").children[1].children]
    assert robot_rows == [["0:11", "warn", "tree", "Patrol: the root failed in ticks 11-12"],
                          ["0:50", "warn", "bumpers", "front bumper pressed"],
                          ["0:55", "warn", "navigation", "failed to reach room2 (FAILED_MOVE)"]]
    log = page.one("section", "log")
    texts = [row.all_text() for row in page.find("tr", section="log")]
    assert any("path <blocked> near room2" in text for text in texts)  # escaped, not a tag
    assert not page.find("blocked") and "replanning" not in log.all_text()  # info left out


def test_the_page_asks_for_nothing_outside_itself(run: tuple[Mission, Page]) -> None:
    _, page = run
    assert not re.search(r"https?:|//[a-z]", page.text.replace("<!--", ""), re.IGNORECASE)
    for element in page.elements:
        for name in ("src", "href", "xlink:href", "action", "data"):
            value = element.attrs.get(name)
            assert value is None or value.startswith("#"), (element.tag, name, value)
    assert not page.find("link") and not page.find("img") and not page.find("iframe")
    assert all(not element.attrs.get("src") for element in page.find("script"))
    assert "url(" not in page.text and "@import" not in page.text


def test_several_robots_get_a_section_each_saying_what_was_not_recorded(
        tmp_path: Path) -> None:
    path = tmp_path / "two.mcap"
    writer = RecordingWriter(path)
    mission(path, writer=writer, rosout=False)
    for step in range(5):
        writer.add("/robot2/pose", Pose2D(x=float(step), y=0.0, theta=0.0), float(step))
    writer.close()
    page = read_page(build_report(path))
    titles = [element.children[0].all_text() for element in page.find("section", "robot")]
    assert titles == ["robot /cyborg", "robot /robot2"]
    assert len(polyline_points(page.one("polyline", "trajectory", robot="robot-1"))) == 5
    second = {name: page.section_text(name, "robot-1")
              for name in ("tree", "battery", "goals", "detections", "path")}
    assert "Not recorded: /robot2/bt/behavior_tree" in second["tree"]
    assert "Not recorded: /robot2/battery_status" in second["battery"]
    assert "Not recorded: /robot2/arnl_path_state, /robot2/current_goal" in second["goals"]
    assert "Not recorded: /robot2/detector/detections" in second["detections"]
    assert "Not recorded: /robot2/map_geometry" in second["path"]
    assert "Not recorded: /rosout" in page.one("section", "log").all_text()


def test_a_tree_reloaded_during_the_run_gets_a_table_per_version(tmp_path: Path) -> None:
    path = tmp_path / "reload.mcap"
    writer = RecordingWriter(path)
    writer.add("/bt/behavior_tree", BehaviorTree(tree=structure(("r", "Root", 0),
                                                                ("a", "A", 1))), 0.0)
    writer.add("/bt/status", tick(1, 1.0, 1, [("a", 1), ("r", 1)]), 1.0)
    writer.add("/bt/behavior_tree", BehaviorTree(tree=structure(("r", "Root", 0),
                                                                ("b", "B", 1))), 2.0)
    for number in (2, 3):
        writer.add("/bt/status", tick(number, float(number), 2, [("b", 2), ("r", 2)]),
                   float(number) + 0.5)
    writer.close()
    page = read_page(build_report(path))
    robots = page.find("section", "robot")
    assert len(robots) == 1 and robots[0].children[0].all_text() == "tree runner /bt"
    tables = page.find("table", "tree")
    assert len(tables) == 2
    second = {row.attrs["data-node"]: row.attrs["data-failure"] for row in tables[1].children[1]
              .children}
    assert second == {"r": "2", "b": "2"}
    assert "Not recorded" not in page.section_text("tree", "robot-0")


def test_goals_are_found_from_the_path_state_alone_and_named_by_current_goal_alone(
        tmp_path: Path) -> None:
    path = tmp_path / "goals.mcap"
    writer = RecordingWriter(path)
    for attempt, state in enumerate(("REACHED_GOAL", "FAILED_PLAN")):
        writer.add("/a/arnl_path_state", String(data="MOVING_TO_GOAL"), attempt * 10.0 + 1)
        writer.add("/a/arnl_path_state", String(data=state), attempt * 10.0 + 5)
    writer.add("/b/current_goal", goal("kitchen"), 1.0)
    writer.add("/b/current_goal", goal(""), 6.0)
    writer.add("/b/battery_status", battery(80.0), 1.0)
    writer.close()
    page = read_page(build_report(path))
    first = page.one("p", "tally", robot="robot-0").attrs
    assert (first["data-reached"], first["data-failed"]) == ("1", "1")
    assert [row.attrs["data-outcome"] for row in page.find("tr", robot="robot-1")
            if "data-outcome" in row.attrs] == ["unknown"]
    assert "kitchen" in page.section_text("goals", "robot-1")


def test_a_long_battery_series_is_downsampled_keeping_its_extremes(tmp_path: Path) -> None:
    path = tmp_path / "long.mcap"
    writer = RecordingWriter(path)
    for second in range(10_000):
        charge = 5.0 if second == 7_777 else 50.0 + (second % 100) * 0.1
        writer.add("/r/battery_status", battery(charge), float(second))
    writer.close()
    page = read_page(build_report(path))
    line = page.one("polyline", "charge")
    points = polyline_points(line)
    assert len(points) <= MAX_CHART_POINTS + 2
    assert int(line.attrs["data-points"]) == len(points)
    assert "lowest 5 %" in page.section_text("battery", "robot-0")
    assert max(y for _, y in points) == pytest.approx(34 + 158 * 0.95, abs=0.01)  # the 5 %
