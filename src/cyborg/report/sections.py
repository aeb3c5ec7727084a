"""The sections of a robot in the report: tree, path, battery, goals, detections, warnings.

Each is drawn from what :mod:`cyborg.report.build` worked out, or is a note saying which
topics were not recorded.

Figures carry their numbers as ``data-`` attributes too (a goal table's reached and failed
counts, a tree row's status counts, a chart line's points), so that a reader's tools, and the
tests, find them without parsing the prose.
"""

from __future__ import annotations

from collections.abc import Sequence
from html import escape

from cyborg.report.battery import BatteryHistory
from cyborg.report.detections import DetectionCounts
from cyborg.report.goals import GoalAttempt, Outcome, tally
from cyborg.report.page import cell, missing, note, row, section, table
from cyborg.report.svg import Periods, Series, clock, number, time_chart
from cyborg.report.tree_stats import STATUSES, TreeHistory, TreeRun
from cyborg.report.warnings import WarningRow

MAX_TABLE_ROWS = 1000
"""The most rows a goals or warnings table lists; the rest are counted under it."""


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
            + table(["node", "success", "failure", "running", "error", "running time (s)",
                     "mean tick time (ms)"], rows, "tree"))
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
    chart = time_chart("charge (%)", [Series("charge", "charge", points)], duration=duration,
                       y_range=(0.0, 100.0), y_unit="%",
                       periods=[Periods("charging", "charging", span(history.charging)),
                                Periods("docked", "docked", span(history.docked))])
    first, last = history.charge[0][1], history.charge[-1][1]
    text = (f"From {number(first, 1)} % to {number(last, 1)} %, lowest "
            f"{number(history.lowest or 0.0, 1)} %; charging {len(history.charging)} times, "
            f"docked {len(history.docked)} times.")
    return section("battery", "Battery", chart + note(text))


def goals_section(attempts: list[GoalAttempt], start: int, topics: Sequence[str],
                  absent: Sequence[str]) -> str:
    """The goals driven to, with their outcome and times."""
    if len(absent) == len(topics):
        return section("goals", "Goals", missing(absent))
    counts = tally(attempts)
    summary = ", ".join(f"{counts[outcome]} {outcome.value}" for outcome in Outcome
                        if counts[outcome] or outcome in (Outcome.REACHED, Outcome.FAILED))
    parts = [missing(absent)] if absent else []
    parts.append(f'<p class="tally" data-reached="{counts[Outcome.REACHED]}" '
                 f'data-failed="{counts[Outcome.FAILED]}" '
                 f'data-cancelled="{counts[Outcome.CANCELLED]}">{escape(summary)}.</p>')
    rows = []
    for attempt in attempts[:MAX_TABLE_ROWS]:
        began = (attempt.start - start) / 1e9
        ended = (attempt.end - start) / 1e9 if attempt.end is not None else None
        rows.append(row(cell(clock(began)),
                        cell(clock(ended) if ended is not None else ""),
                        cell(float(number(ended - began, 1))) if ended is not None else cell(""),
                        cell(attempt.name or "(unnamed)"),
                        cell(attempt.outcome.value, f"outcome {attempt.outcome.value}"),
                        cell(attempt.state),
                        attributes=f'data-outcome="{attempt.outcome.value}"'))
    if attempts:
        parts.append(table(["start", "end", "took (s)", "goal", "outcome", "path state"], rows,
                           "goals"))
    if len(attempts) > MAX_TABLE_ROWS:
        parts.append(note(f"and {len(attempts) - MAX_TABLE_ROWS} more goals"))
    return section("goals", "Goals", "".join(parts))


def detections_section(counts: DetectionCounts, duration: float, topics: Sequence[str]) -> str:
    """Objects seen per minute and class: a chart of the most frequent classes and a table."""
    if not counts.source:
        return section("detections", "Detections", missing(topics))
    classes = counts.classes
    minutes = range(int(duration // 60) + 1)
    if not classes:
        return section("detections", "Detections",
                       note(f"{counts.source}: recorded, no object seen."))
    series = [Series(label, f"c{colour}", [(minute * 60.0 + 30.0, float(counts.seen(minute, label)))
                                           for minute in minutes])
              for colour, label in enumerate(classes[:5])]
    chart = time_chart("objects per minute", series, duration=max(duration, 60.0))
    rows = [row(cell(f"{minute}"), *(cell(counts.seen(minute, label)) for label in classes),
                attributes=f'data-minute="{minute}"')
            for minute in minutes if minute in counts.per_minute]
    totals = counts.totals
    rows.append(row(cell("all"), *(cell(totals[label]) for label in classes),
                    attributes='class="total"'))
    return section("detections", "Detections",
                   chart + table(["minute", *classes], rows, "detections")
                   + note(f"Counted from {counts.source}."))


def warnings_section(rows_in: list[WarningRow], start: int) -> str:
    """A table of what went wrong, or a note that nothing did."""
    if not rows_in:
        return section("warnings", "Warnings", note("Nothing went wrong that the recording "
                                                     "shows."))
    return section("warnings", "Warnings", warnings_table(rows_in, start))


def warnings_table(rows_in: list[WarningRow], start: int) -> str:
    """The rows of a warnings table (at most :data:`MAX_TABLE_ROWS`)."""
    rows = [row(cell(clock((item.log_time - start) / 1e9)), cell(item.level, f"level "
                                                                 f"{item.level}"),
                cell(item.source), cell(item.text))
            for item in rows_in[:MAX_TABLE_ROWS]]
    extra = (note(f"and {len(rows_in) - MAX_TABLE_ROWS} more")
             if len(rows_in) > MAX_TABLE_ROWS else "")
    return table(["time", "level", "source", "text"], rows, "warnings") + extra

