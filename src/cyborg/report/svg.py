"""Inline SVG for a report: a time chart with shaded periods, and number formatting.

Everything is written as text into the page (no script draws it), so a report shows in any
browser, prints, and is searchable. Texts are escaped; numbers are rounded to what a reader can
see. :func:`downsample` keeps a long series small while keeping its shape: per bucket of time,
the lowest and the highest value.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from html import escape

WIDTH = 760
"""Width of a chart (SVG user units; it scales with the page)."""
HEIGHT = 220
MARGIN = (34, 12, 28, 46)
"""Top, right, bottom, left margins of a chart's plot area."""
MAX_CHART_POINTS = 2000
"""The most points one chart line holds; longer series are downsampled."""


@dataclass(frozen=True)
class Series:
    """One line of a chart: its name, CSS class and (seconds, value) points."""

    name: str
    css: str
    points: Sequence[tuple[float, float]]


@dataclass(frozen=True)
class Periods:
    """Shaded spans of a chart: their name, CSS class and (start, end) seconds."""

    name: str
    css: str
    spans: Sequence[tuple[float, float]]


def number(value: float, digits: int = 2) -> str:
    """``value`` rounded to ``digits`` decimals, without trailing zeros (``1.5``, ``-0.25``)."""
    text = f"{value:.{digits}f}".rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text


def downsample(points: Sequence[tuple[float, float]],
               limit: int = MAX_CHART_POINTS) -> list[tuple[float, float]]:
    """At most about ``limit`` points of ``points`` (in time order), keeping the shape.

    Each bucket of time keeps its lowest and highest value, in their order; the first and the
    last point are always kept.
    """
    if len(points) <= limit:
        return list(points)
    buckets = max(1, limit // 2)
    size = len(points) / buckets
    kept: list[tuple[float, float]] = []
    for bucket in range(buckets):
        part = points[int(bucket * size):int((bucket + 1) * size)]
        if not part:
            continue
        low = min(range(len(part)), key=lambda i: part[i][1])
        high = max(range(len(part)), key=lambda i: part[i][1])
        kept += [part[i] for i in sorted({low, high})]
    if kept[0] != points[0]:
        kept.insert(0, points[0])
    if kept[-1] != points[-1]:
        kept.append(points[-1])
    return kept


def _ticks(low: float, high: float, count: int = 5) -> list[float]:
    """Round numbers between ``low`` and ``high`` for an axis."""
    span = high - low
    if span <= 0:
        return [low]
    raw = span / count
    step = 10 ** math.floor(math.log10(raw))
    for factor in (1, 2, 5, 10):
        if step * factor >= raw:
            step *= factor
            break
    first = math.ceil(low / step) * step
    return [first + i * step for i in range(int((high - first) / step + 1e-9) + 1)]


def time_chart(title: str, series: Sequence[Series], *, duration: float,
               y_range: tuple[float, float] | None = None, y_unit: str = "",
               periods: Sequence[Periods] = (), css: str = "chart") -> str:
    """An SVG chart of ``series`` over ``duration`` seconds, with ``periods`` shaded behind.

    Each series is a ``<polyline>`` of class ``line <css>`` whose ``data-points`` attribute
    says how many points it holds (after :func:`downsample`); a legend names series and periods.
    """
    top, right, bottom, left = MARGIN
    plot_w, plot_h = WIDTH - left - right, HEIGHT - top - bottom
    values = [value for line in series for _, value in line.points]
    low, high = y_range or ((min(values), max(values)) if values else (0.0, 1.0))
    if high <= low:
        low, high = low - 1.0, high + 1.0
    end = max(duration, 1e-9)

    def x(seconds: float) -> float:
        return left + plot_w * min(max(seconds / end, 0.0), 1.0)

    def y(value: float) -> float:
        return top + plot_h * (1.0 - (value - low) / (high - low))

    parts = [f'<svg class="{escape(css)}" viewBox="0 0 {WIDTH} {HEIGHT}" role="img" '
             f'aria-label="{escape(title)}">',
             f'<text class="title" x="{left}" y="14">{escape(title)}</text>']
    for shaded in periods:
        for start, stop in shaded.spans:
            parts.append(f'<rect class="period {escape(shaded.css)}" x="{number(x(start))}" '
                         f'y="{top}" width="{number(max(x(stop) - x(start), 0.5))}" '
                         f'height="{plot_h}"><title>{escape(shaded.name)}: '
                         f'{number(start, 1)}-{number(stop, 1)} s</title></rect>')
    for tick in _ticks(low, high, 4):
        parts.append(f'<line class="grid" x1="{left}" x2="{left + plot_w}" y1="{number(y(tick))}" '
                     f'y2="{number(y(tick))}"/><text class="axis" x="{left - 4}" '
                     f'y="{number(y(tick) + 4)}" text-anchor="end">{number(tick)}{escape(y_unit)}'
                     '</text>')
    for tick in _ticks(0.0, end, 6):
        parts.append(f'<text class="axis" x="{number(x(tick))}" y="{HEIGHT - 10}" '
                     f'text-anchor="middle">{clock(tick)}</text>')
    parts.append(f'<rect class="frame" x="{left}" y="{top}" width="{plot_w}" height="{plot_h}"/>')
    for line in series:
        points = downsample(line.points)
        text = " ".join(f"{number(x(t))},{number(y(v))}" for t, v in points)
        parts.append(f'<polyline class="line {escape(line.css)}" data-points="{len(points)}" '
                     f'points="{text}"><title>{escape(line.name)}</title></polyline>')
    legend_x = left  # the legend's line lies between the title's and the plot
    for name, css_class in [(line.name, line.css) for line in series] + \
            [(shaded.name, shaded.css) for shaded in periods if shaded.spans]:
        parts.append(f'<rect class="key {escape(css_class)}" x="{legend_x}" y="19" width="12" '
                     f'height="10"/><text class="axis" x="{legend_x + 16}" y="28">'
                     f'{escape(name)}</text>')
        legend_x += 24 + 7 * len(name)
    parts.append("</svg>")
    return "".join(parts)


def clock(seconds: float) -> str:
    """Seconds as ``m:ss`` (``h:mm:ss`` from an hour on), for axes and tables."""
    whole = round(seconds)
    hours, rest = divmod(whole, 3600)
    minutes, secs = divmod(rest, 60)
    return f"{hours}:{minutes:02d}:{secs:02d}" if hours else f"{minutes}:{secs:02d}"
