"""The report's page: one HTML file with its own style and script, and helpers for its parts.

Tables, sections and notes are written by the helpers here.

The page asks for nothing: no stylesheet, script, font or image is fetched, so it opens from a
file, mailed or archived, with no server and no network. Every text that comes from a
recording (topic names, goal and node names, log messages) is escaped where it is written.
The script only adds comfort — folding the tree's rows and showing the map's coordinates under
the pointer —; everything is readable without it.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from html import escape

STYLE = """
:root { color-scheme: light; --ink: #1d2327; --muted: #5f6b73; --line: #d5dbe0;
  --teal: #0f8b8d; --red: #c0392b; --amber: #d68910; --purple: #7d3c98; --green: #1e8449; }
body { font: 14px/1.45 system-ui, sans-serif; color: var(--ink); margin: 0 auto;
  max-width: 1100px; padding: 16px 24px 48px; }
h1 { font-size: 22px; margin: 8px 0 4px; } h2 { font-size: 18px; margin: 32px 0 8px;
  border-bottom: 2px solid var(--line); padding-bottom: 4px; } h3 { font-size: 15px;
  margin: 20px 0 6px; }
table { border-collapse: collapse; margin: 6px 0; } th, td { padding: 2px 10px 2px 0;
  text-align: left; vertical-align: top; border-bottom: 1px solid var(--line); }
.scroll { max-width: 100%; overflow-x: auto; } thead th { vertical-align: bottom; }
.meta td { overflow-wrap: anywhere; } .meta th { white-space: nowrap; }
td.state[title] { text-decoration: underline dotted; cursor: help; }
dl.legend { margin: 6px 0; font-size: 13px; } dl.legend dt { font-weight: 600; }
dl.legend dd { margin: 0 0 4px 16px; color: var(--muted); }
@media (max-width: 600px) { body { padding: 8px 10px 32px; } h1 { font-size: 18px; }
  h1, p, .note, .missing, summary { overflow-wrap: anywhere; } }
td.n, th.n { text-align: right; font-variant-numeric: tabular-nums; }
.meta th { color: var(--muted); font-weight: normal; }
.cut, .missing, .note { padding: 6px 10px; border-radius: 4px; margin: 6px 0; }
.cut { background: #fdecea; border-left: 4px solid var(--red); }
.missing { background: #f4f6f7; color: var(--muted); border-left: 4px solid var(--line); }
.note { color: var(--muted); }
nav { display: flex; flex-wrap: wrap; gap: 4px 12px; }
svg { display: block; width: 100%; height: auto; margin: 6px 0; }
svg.map { max-height: 640px; background: #fafbfc; border: 1px solid var(--line); }
.map .points { stroke: #9aa5ad; fill: none; } .map .walls { stroke: #2c3e50; fill: none; }
.map .forbidden { stroke: var(--red); fill: rgba(192, 57, 43, .12); stroke-dasharray: 1 .6; }
.map .goal circle { fill: var(--teal); } .map .dock circle { fill: var(--purple); }
.map .home circle { fill: var(--green); } .map text { fill: var(--muted); }
.map .trajectory { stroke: var(--amber); fill: none; stroke-linejoin: round; }
.map .start { fill: var(--green); } .map .end { fill: var(--red); }
.map .attempt { fill: none; stroke-width: calc(var(--unit) * .4); }
.map .attempt.reached { stroke: var(--green); } .map .attempt.failed { stroke: var(--red); }
.map .attempt.cancelled, .map .attempt.unfinished, .map .attempt.unknown { stroke: var(--muted); }
.chart .title { font-weight: bold; font-size: 12px; } .chart .axis { font-size: 11px;
  fill: var(--muted); } .chart .grid { stroke: #eef1f3; } .chart .frame { fill: none;
  stroke: var(--line); } .chart .line { fill: none; stroke-width: 1.5; }
.line.charge, .key.charge { stroke: var(--teal); fill: var(--teal); }
.period.charging, .key.charging { fill: rgba(30, 132, 73, .15); }
.period.docked, .key.docked { fill: rgba(125, 60, 152, .12); }
.line.c0, .key.c0 { stroke: var(--teal); fill: var(--teal); }
.line.c1, .key.c1 { stroke: var(--amber); fill: var(--amber); }
.line.c2, .key.c2 { stroke: var(--purple); fill: var(--purple); }
.line.c3, .key.c3 { stroke: var(--red); fill: var(--red); }
.line.c4, .key.c4 { stroke: var(--green); fill: var(--green); }
.chart .line { fill: none; }
.tree td.label { white-space: nowrap; } .tree .category { color: var(--muted); font-size: 12px; }
.tree tr.folder td.label { cursor: pointer; } .tree tr.folded td.label::after { content: " …"; }
.outcome.reached { color: var(--green); } .outcome.failed { color: var(--red); }
.level.warn { color: var(--amber); } .level.error, .level.fatal { color: var(--red); }
#pointer { color: var(--muted); font-size: 12px; min-height: 1.2em; }
"""

SCRIPT = """
for (const table of document.querySelectorAll("table.tree")) {
  const rows = [...table.tBodies[0].rows];
  rows.forEach((row, i) => {
    const depth = +row.dataset.depth;
    const next = rows[i + 1];
    if (!next || +next.dataset.depth <= depth) return;
    row.classList.add("folder");
    row.cells[0].addEventListener("click", () => {
      const fold = row.classList.toggle("folded");
      for (let j = i + 1; j < rows.length && +rows[j].dataset.depth > depth; j++) {
        rows[j].hidden = fold;
        if (!fold) rows[j].classList.remove("folded");
      }
    });
  });
}
for (const svg of document.querySelectorAll("svg.map")) {
  const out = svg.parentElement.querySelector(".pointer");
  if (!out) continue;
  svg.addEventListener("pointermove", (event) => {
    const matrix = svg.getScreenCTM();
    if (!matrix) return;
    const point = new DOMPoint(event.clientX, event.clientY).matrixTransform(matrix.inverse());
    out.textContent = `x ${point.x.toFixed(2)} m, y ${(-point.y).toFixed(2)} m`;
  });
}
"""


def cell(value: object, css: str = "") -> str:
    """A table cell holding ``value`` as escaped text (numbers right-aligned)."""
    numeric = isinstance(value, int | float) and not isinstance(value, bool)
    classes = " ".join(part for part in (css, "n" if numeric else "") if part)
    attribute = f' class="{classes}"' if classes else ""
    return f"<td{attribute}>{escape(str(value))}</td>"


def table(headers: Sequence[str], rows: Iterable[str], css: str = "") -> str:
    """A table with ``headers`` and ready-made ``<tr>`` rows.

    It scrolls sideways in a box of its own when it is wider than the page (on a phone), so
    the page itself never does.
    """
    head = "".join(f"<th>{escape(header)}</th>" for header in headers)
    attribute = f' class="{escape(css)}"' if css else ""
    thead = f"<thead><tr>{head}</tr></thead>" if headers else ""
    return (f'<div class="scroll"><table{attribute}>{thead}<tbody>{"".join(rows)}</tbody>'
            "</table></div>")


def row(*cells: str, attributes: str = "") -> str:
    """A ``<tr>`` of ready-made cells."""
    return f"<tr{(' ' + attributes) if attributes else ''}>{''.join(cells)}</tr>"


def section(css: str, title: str, body: str, *, level: int = 3, anchor: str = "") -> str:
    """A titled section (``<h2>`` or ``<h3>``) of class ``css``."""
    identifier = f' id="{escape(anchor)}"' if anchor else ""
    return (f'<section class="{escape(css)}"{identifier}><h{level}>{escape(title)}</h{level}>'
            f"{body}</section>")


def missing(topics: Sequence[str], what: str = "") -> str:
    """The note a section shows instead of its figures: which topics were not recorded."""
    names = ", ".join(topics)
    reason = f" ({what})" if what else ""
    return f'<p class="missing">Not recorded: {escape(names)}{escape(reason)}.</p>'


def note(text: str) -> str:
    """A short remark under a figure."""
    return f'<p class="note">{escape(text)}</p>'


def document(title: str, body: str) -> str:
    """The whole page around ``body``, with its style and script."""
    return ("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
            "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">"
            f"<title>{escape(title)}</title><style>{STYLE}</style></head><body>{body}"
            f"<script>{SCRIPT}</script></body></html>\n")
