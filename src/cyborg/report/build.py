"""``cyborg report``'s work: a recording in, one self-contained HTML page out.

:func:`build_report` reads the recording (:mod:`cyborg.report.recording`), finds its robots
(:mod:`cyborg.report.robots`) and gives each a section with its tree, its path on the map, its
battery, its goals, its detections and its warnings; above them a header names the file, the
run's metadata (cyborg version, start, command, map and tree files), its duration (on the
wall clock, and in simulated time when a simulator's ``/clock`` was recorded:
:mod:`cyborg.report.clocks`) and the messages of every topic, and says so when the file was
cut. Below them the log's warnings
(``/rosout``, when recorded) and what could not be read. :func:`write_report` writes the page.
"""

from __future__ import annotations

import itertools
import math
from html import escape
from pathlib import Path
from typing import Any

from cyborg.interfaces import detector, perception, robot, tree_runner
from cyborg.interfaces.contract import Topic
from cyborg.record.recorder import MAP_METADATA, RUN_METADATA
from cyborg.report import sections
from cyborg.report.battery import battery_history
from cyborg.report.clocks import CLOCK_SAMPLE_NS, RunClock, run_clock
from cyborg.report.detections import detection_counts, tracked_counts
from cyborg.report.goals import goal_attempts, measure_left
from cyborg.report.map_svg import map_svg
from cyborg.report.page import cell, document, note, row, section, table
from cyborg.report.recording import Recording, read_recording
from cyborg.report.robots import CLOCK_TOPIC, LOG_TOPIC, RobotTopics, find_robots, wanted
from cyborg.report.svg import clock, number
from cyborg.report.tree_stats import tree_history
from cyborg.report.warnings import log_warnings, robot_warnings

_RUN_FIELDS = (("cyborg_version", "cyborg version"), ("started", "started"),
               ("command", "command"), ("map", "map file"), ("tree", "tree file"))


def build_report(path: Path) -> str:
    """The report of the recording at ``path`` as HTML text.

    Raises :class:`~cyborg.record.playback_source.RecordingError` naming the file when it is no
    recording (empty, foreign, cut inside its header) or cannot be read.
    """
    return render(read(path))


def read(path: Path) -> Recording:
    """The recording at ``path`` as a report reads it: the topics it draws, ``/clock`` sampled."""
    return read_recording(path, wanted, every={CLOCK_TOPIC: CLOCK_SAMPLE_NS})


def render(recording: Recording) -> str:
    """The report of a recording read with :func:`read`."""
    robots = find_robots({name: topic.type_name for name, topic in recording.topics.items()})
    clock = run_clock(recording.stamped(CLOCK_TOPIC))
    body = [_header(recording, robots, clock)]
    body += [_robot(recording, item, index, clock) for index, item in enumerate(robots)]
    if not robots:
        body.append(section("robots", "Robots", note(
            "No robot or tree runner in this recording: none of its topics is a robot's "
            f"({robot.POSE.name}, {robot.BATTERY_STATUS.name}, ...) or a tree runner's "
            f"({tree_runner.STRUCTURE.name}, {tree_runner.STATUS.name})."), level=2))
    body.append(_log(recording))
    return document(f"Run report: {recording.path.name}", "".join(body))


def write_report(path: Path, output: Path) -> Recording:
    """Writes the report of ``path`` to ``output``; returns what was read (for a summary)."""
    recording = read(path)
    output.write_text(render(recording), encoding="utf-8")
    return recording


def _header(recording: Recording, robots: list[RobotTopics], clock: RunClock | None) -> str:
    run = recording.metadata_named(RUN_METADATA)
    values = run[-1] if run else {}
    rows = [row(f"<th>{escape(label)}</th>", cell(values[key]))
            for key, label in _RUN_FIELDS if values.get(key)]
    for item in recording.metadata_named(MAP_METADATA):
        rows.append(row("<th>map published</th>",
                        cell(f"{item.get('source', '?')} on {item.get('topic', '?')}")))
    rows += [row("<th>file</th>", cell(f"{recording.path.name} ({_size(recording.size)})")),
             row("<th>duration</th>", cell(_duration(recording.duration, clock))),
             row("<th>messages</th>", cell(f"{recording.message_count:,} on "
                                           f"{len(recording.topics)} topics"))]
    parts = [f"<h1>Run report: {escape(recording.path.name)}</h1>"]
    if recording.cut:
        parts.append(f'<p class="cut">This file was cut ({escape(recording.cut)}): the report '
                     "shows what was readable up to there. <code>cyborg record --recover</code> "
                     "makes an indexed copy of it.</p>")
    if not run:
        parts.append(note("The recording names no run (no cyborg metadata): it was not made "
                          "by cyborg record."))
    parts.append(table([], rows, "meta"))
    if robots:
        links = "".join(f'<a href="#robot-{index}">{escape(item.title)}</a>'
                        for index, item in enumerate(robots))
        parts.append(f"<nav>{links}</nav>")
    topic_rows = [row(cell(topic.name), cell(topic.type_name), cell(topic.count))
                  for topic in sorted(recording.topics.values(), key=lambda t: t.name)]
    parts.append(f"<details><summary>Messages per topic</summary>"
                 f"{table(['topic', 'type', 'messages'], topic_rows, 'topics')}</details>")
    return "<header>" + "".join(parts) + "</header>"


def _robot(recording: Recording, item: RobotTopics, index: int, clock: RunClock | None) -> str:
    recorded = recording.topics

    def name(contract: Topic[Any]) -> str:
        return item.topic(contract)

    def absent(*contracts: Topic[Any]) -> list[str]:
        return [name(contract) for contract in contracts if name(contract) not in recorded]

    start = recording.start
    end = recording.end
    tree = tree_history(recording.stamped(name(tree_runner.STRUCTURE)),
                        recording.stamped(name(tree_runner.STATUS)))
    goals = goal_attempts(recording.stamped(name(robot.PATH_STATE)),
                          recording.stamped(name(robot.CURRENT_GOAL)))
    parts = [sections.tree_section(tree, absent(tree_runner.STRUCTURE, tree_runner.STATUS)
                                   or [name(tree_runner.STRUCTURE)])]
    if item.has_robot:
        stamped_poses = recording.stamped(name(robot.POSE))
        measure_left(goals, stamped_poses)
        poses = [(float(p.message.x), float(p.message.y)) for p in stamped_poses]
        maps = recording.stamped(name(robot.MAP_GEOMETRY))
        geometry = maps[-1].message if maps else None
        parts.append(sections.map_section(
            map_svg(geometry, poses, goals), _distance(poses),
            [name(robot.POSE), name(robot.MAP_GEOMETRY)], geometry is not None, bool(poses)))
        parts.append(sections.battery_section(
            battery_history(recording.stamped(name(robot.BATTERY_STATUS)), end),
            recording.duration, start, name(robot.BATTERY_STATUS)))
        parts.append(sections.goals_section(
            goals, start, [name(robot.PATH_STATE), name(robot.CURRENT_GOAL)],
            absent(robot.PATH_STATE, robot.CURRENT_GOAL), clock))
        counts = detection_counts(
            (name(detector.DETECTIONS), recording.stamped(name(detector.DETECTIONS))),
            (name(detector.PREDICTIONS), recording.stamped(name(detector.PREDICTIONS))), start)
        tracked = tracked_counts(name(perception.OBJECTS),
                                 recording.stamped(name(perception.OBJECTS)), start)
        parts.append(sections.detections_section(
            tracked, counts, recording.duration, name(perception.OBJECTS),
            [name(detector.DETECTIONS), name(detector.PREDICTIONS)]))
    parts.append(sections.warnings_section(
        robot_warnings(goals, tree, recording.stamped(name(robot.BUMPER_STATE))), start))
    return section("robot", item.title, "".join(parts), level=2, anchor=f"robot-{index}")


def _duration(wall: float, run: RunClock | None) -> str:
    """The recording's duration on the wall clock, and in simulated time where that differs."""
    text = f"{clock(wall)} wall clock (first to last message)"
    if run is None:
        return text + "; no /clock recorded: every time in this report is wall time"
    if not run.differs:
        return text + "; simulated time (/clock) kept the wall clock's pace"
    return (f"{text}; {clock(run.duration)} simulated time (/clock), {number(run.pace, 1)}x "
            "the wall clock")


def _size(size: int) -> str:
    return f"{number(size / 1e6, 1)} MB" if size >= 100_000 else f"{number(size / 1e3, 1)} kB"


def _distance(poses: list[tuple[float, float]]) -> float:
    finite = [(x, y) for x, y in poses if math.isfinite(x) and math.isfinite(y)]
    return sum(math.dist(a, b) for a, b in itertools.pairwise(finite))


def _log(recording: Recording) -> str:
    parts = []
    if LOG_TOPIC in recording.topics:
        rows = log_warnings(recording.stamped(LOG_TOPIC))
        parts.append(sections.warnings_table(rows, recording.start) if rows else
                     note(f"{LOG_TOPIC}: recorded, no warning."))
    else:
        parts.append(note(f"Not recorded: {LOG_TOPIC}. cyborg's components log to their "
                          "terminal, not onto the bus; each robot's warnings above come from "
                          "what the recording shows."))
    parts += [note(problem) for problem in recording.problems]
    return section("log", "Log", "".join(parts), level=2, anchor="log")
