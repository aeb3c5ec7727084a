"""The sections of a robot in the report: tree, path, battery, goals, detections, warnings.

Each is drawn from what :mod:`cyborg.report.build` worked out, or is a note saying which
topics were not recorded.

Figures carry their numbers as ``data-`` attributes too (a goal table's reached and failed
counts, a tree row's status counts, a chart line's points), so that a reader's tools, and the
tests, find them without parsing the prose.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Sequence
from html import escape

from cyborg.report.battery import BatteryHistory
from cyborg.report.clocks import RunClock
from cyborg.report.detections import DetectionCounts
from cyborg.report.goals import PATH_STATES, GoalAttempt, Outcome, tally
from cyborg.report.page import cell, missing, note, row, section, table
from cyborg.report.svg import Periods, Series, number, time_chart
from cyborg.report.svg import clock as m_ss
from cyborg.report.tree_stats import STATUSES, TreeHistory, TreeRun
from cyborg.report.warnings import WarningRow

MAX_TABLE_ROWS = 1000
"""The most rows a goals or warnings table lists; the rest are counted under it."""
WALL_AXIS = "wall time since the recording began"
"""How a chart names its time axis: every chart is drawn on the recording's wall clock."""


def tree_section(history: TreeHistory, topics: Sequence[str]) -> str:
    """Per-node status counts and times of every tree version the runner published."""
    if not history.runs:
        return section("tree", "Tree", missing(topics) + "".join(
            note(problem) for problem in history.problems))
    parts = []
    for run in history.runs:
        parts.append(_tree_run(run, multiple=len(history.runs) > 1))
    if history.orphan_ticks:
        parts.append(note(f"{history.orphan_ticks} ticks came before the tree's structure and "
                          "are not counted."))
    parts += [note(problem) for problem in history.problems]
    return section("tree", "Tree", "".join(parts))


def _tree_run(run: TreeRun, *, multiple: bool) -> str:
    outline = run.outline
    rows = []
    for index, uid in enumerate(outline.ids):
        stats = run.nodes[index]
        indent = "\u2003" * outline.depths[index]
        label = (f'<td class="label">{indent}{escape(outline.labels[index])} '
                 f'<span class="category">{escape(outline.categories[index])}</span></td>')
        counts = [cell(stats.counts[status]) for status in STATUSES]
        mean = stats.tick_time / stats.timed * 1000.0 if stats.timed else None
        attributes = (f'data-node="{escape(uid)}" data-depth="{outline.depths[index]}" '
                      + " ".join(f'data-{status.label}="{stats.counts[status]}"'
                                 for status in STATUSES))
        rows.append(row(label, *counts, cell(float(number(stats.running_time, 1))),
                        cell(float(number(mean, 3))) if mean is not None else cell(""),
                        attributes=attributes))
    heading = f"{run.title}: {run.ticks} ticks"
    if run.ticks:
        heading += f" ({run.first_tick}-{run.last_tick})"
    roots = ", ".join(f"{run.root_counts[status]} {status.label}" for status in STATUSES
                      if run.root_counts[status])
    body = (f'<p data-ticks="{run.ticks}">{escape(heading)}'
            f'{escape("; the root returned " + roots) if roots else ""}.</p>'
            + table(["node", "success", "failure", "running", "error",
                     "running time (s, tree clock)", "mean tick time (ms, wall)"], rows, "tree"))
    explained = note("Counts are ticks in which the node returned each status. Running time is "
                     "the tree's clock (simulated time under a simulator) from each tick the "
                     "node returned running to the next tick; tick time is the wall time its "
                     "visits took, subtree included.")
    return (f"<h4>{escape(run.title)}</h4>" if multiple else "") + body + explained


def map_section(svg: str, driven: float, topics: Sequence[str], have_map: bool,
                have_poses: bool) -> str:
    """The path driven on the map, or what was not recorded."""
    absent = [topic for topic, present in zip(topics, (have_poses, have_map), strict=True)
              if not present]
    parts = [missing(absent)] if absent else []
    if svg:
        parts.append(svg)
        parts.append('<p class="pointer"></p>')
    if have_poses:
        parts.append(note(f"Driven: {number(driven, 1)} m (orange; green dot the start, red the "
                          "end). Rings mark the goals driven to: green reached, red failed."))
    return section("path", "Path driven", "".join(parts))


def battery_section(history: BatteryHistory, duration: float, start: int, topic: str) -> str:
    """The charge over time with the charging and docked periods shaded."""
    if not history.charge:
        return section("battery", "Battery", missing([topic]))

    def span(pairs: list[tuple[int, int]]) -> list[tuple[float, float]]:
        return [((a - start) / 1e9, (b - start) / 1e9) for a, b in pairs]

    points = [((when - start) / 1e9, value) for when, value in history.charge]
    chart = time_chart(f"charge (%) by {WALL_AXIS}", [Series("charge", "charge", points)],
                       duration=duration,
                       y_range=(0.0, 100.0), y_unit="%",
                       periods=[Periods("charging", "charging", span(history.charging)),
                                Periods("docked", "docked", span(history.docked))])
    first, last = history.charge[0][1], history.charge[-1][1]
    text = (f"From {number(first, 1)} % to {number(last, 1)} %, lowest "
            f"{number(history.lowest or 0.0, 1)} %; charging {len(history.charging)} times, "
            f"docked {len(history.docked)} times.")
    return section("battery", "Battery", chart + note(text))


def goals_section(attempts: list[GoalAttempt], start: int, topics: Sequence[str],
                  absent: Sequence[str], clock: RunClock | None = None) -> str:
    """The goals driven to: outcome, times (both clocks where they differ), path states' legend."""
    if len(absent) == len(topics):
        return section("goals", "Goals", missing(absent))
    counts = tally(attempts)
    summary = ", ".join(f"{counts[outcome]} {outcome.value}" for outcome in Outcome
                        if counts[outcome] or outcome in (Outcome.REACHED, Outcome.FAILED))
    parts = [missing(absent)] if absent else []
    parts.append(f'<p class="tally" data-reached="{counts[Outcome.REACHED]}" '
                 f'data-failed="{counts[Outcome.FAILED]}" '
                 f'data-cancelled="{counts[Outcome.CANCELLED]}">{escape(summary)}.</p>')
    simulated = clock is not None and clock.differs
    rows = []
    for attempt in attempts[:MAX_TABLE_ROWS]:
        began = (attempt.start - start) / 1e9
        ended = (attempt.end - start) / 1e9 if attempt.end is not None else None
        took = [cell(float(number(ended - began, 1))) if ended is not None else cell("")]
        if simulated:
            assert clock is not None
            took.append(cell(float(number(clock.simulated_span(attempt.start, attempt.end), 1)))
                        if attempt.end is not None else cell(""))
        meaning = PATH_STATES.get(attempt.state, "")
        state = (f'<td class="state" title="{escape(meaning)}">{escape(attempt.state)}</td>'
                 if meaning else cell(attempt.state))
        rows.append(row(cell(m_ss(began)), cell(m_ss(ended) if ended is not None else ""),
                        *took, cell(attempt.name or "(unnamed)"),
                        cell(attempt.outcome.value, f"outcome {attempt.outcome.value}"), state,
                        cell(float(number(attempt.left, 1))) if attempt.left is not None
                        else cell(""), attributes=f'data-outcome="{attempt.outcome.value}"'))
    if attempts:
        headers = ["start (wall)", "end (wall)", "took (s, wall)",
                   *(["took (s, simulated)"] if simulated else []), "goal", "outcome",
                   "path state", "left to go (m)"]
        parts.append(table(headers, rows, "goals"))
    if len(attempts) > MAX_TABLE_ROWS:
        parts.append(note(f"and {len(attempts) - MAX_TABLE_ROWS} more goals"))
    parts.append(_states_legend([attempt.state for attempt in attempts]))
    both = (f" Took: on the wall clock (the recorder's), and in simulated time (the "
            f"simulator's /clock, which ran {number(clock.pace, 1)}x as fast)."
            if simulated and clock is not None else "")
    parts.append(note("Start and end are wall time since the recording began (m:ss)." + both
                      + " Left to go: the robot's distance to the goal when the attempt ended."))
    return section("goals", "Goals", "".join(parts))


def _states_legend(states: Sequence[str]) -> str:
    """What each path state that ``states`` holds means, the most frequent first."""
    counts = Counter(state for state in states if state in PATH_STATES)
    if not counts:
        return ""
    items = "".join(f'<dt data-state="{escape(state)}">{escape(state)} ({count})</dt>'
                    f"<dd>{escape(PATH_STATES[state])}</dd>"
                    for state, count in counts.most_common())
    return f'<dl class="legend states">{items}</dl>'


def detections_section(tracked: DetectionCounts, detected: DetectionCounts, duration: float,
                       tracked_topic: str, detected_topics: Sequence[str]) -> str:
    """What the robot saw per minute and class, two counts each named for what it counts.

    The objects its tracker followed (distinct track ids) and its detector's detections (one
    per object per camera frame).
    """
    parts = []
    if tracked.source:
        parts.append(_counts(tracked, duration, "tracked", "objects tracked per minute (distinct "
                             f"track ids), by {WALL_AXIS}"))
        if tracked.classes:
            people = ", ".join(f"{label}: {tracked.totals[label]}" for label in tracked.classes)
            parts.append(note(f"Tracked objects, counted from {tracked.source}: each object the "
                              "robot's tracker followed counts once a minute and once in all "
                              f"({people}); one it lost and found again counts again."))
    else:
        parts.append(missing([tracked_topic], "the tracker's objects"))
    if detected.source:
        parts.append(_counts(detected, duration, "detections", "detections per minute (one per "
                             f"object per camera frame), by {WALL_AXIS}"))
        if detected.classes:
            parts.append(note(f"Detections, counted from {detected.source}: every object in "
                              "every camera frame, so one person in view for a minute counts "
                              "hundreds of times."))
    else:
        parts.append(missing(detected_topics))
    return section("detections", "Detections", "".join(parts))


def _counts(counts: DetectionCounts, duration: float, css: str, title: str) -> str:
    """A chart of the most frequent classes per minute, and a table of all of them."""
    classes = counts.classes
    if not classes:
        return note(f"{counts.source}: recorded, no object seen.")
    minutes = range(int(duration // 60) + 1)
    series = [Series(label, f"c{colour}", [(minute * 60.0 + 30.0, float(counts.seen(minute, label)))
                                           for minute in minutes])
              for colour, label in enumerate(classes[:5])]
    chart = time_chart(title, series, duration=max(duration, 60.0))
    rows = [row(cell(f"{minute}"), *(cell(counts.seen(minute, label)) for label in classes),
                attributes=f'data-minute="{minute}"')
            for minute in minutes if minute in counts.per_minute]
    totals = counts.totals
    rows.append(row(cell("all"), *(cell(totals[label]) for label in classes),
                    attributes='class="total"'))
    return chart + table(["minute", *classes], rows, css)


def warnings_section(rows_in: list[WarningRow], start: int) -> str:
    """A table of what went wrong, or a note that nothing did."""
    if not rows_in:
        return section("warnings", "Warnings", note("Nothing went wrong that the recording "
                                                     "shows."))
    return section("warnings", "Warnings", warnings_table(rows_in, start))


def warnings_table(rows_in: list[WarningRow], start: int) -> str:
    """The rows of a warnings table (at most :data:`MAX_TABLE_ROWS`)."""
    rows = [row(cell(m_ss((item.log_time - start) / 1e9)), cell(item.level, f"level "
                                                                 f"{item.level}"),
                cell(item.source), cell(item.text))
            for item in rows_in[:MAX_TABLE_ROWS]]
    extra = (note(f"and {len(rows_in) - MAX_TABLE_ROWS} more")
             if len(rows_in) > MAX_TABLE_ROWS else "")
    return table(["time (wall)", "level", "source", "text"], rows, "warnings") + extra

