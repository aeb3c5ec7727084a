"""A benchmark's results: rows of (measure, result, ratio, goal), as text or as Markdown.

``--markdown`` prints the rows for docs/benchmarks.md under their header line; plain text
aligns them in columns of the given widths for a terminal.
"""

from __future__ import annotations

from collections.abc import Sequence

COLUMNS = ("measure", "result", "ratio", "goal")
"""The four columns' names, in the Markdown table's header."""


def print_results(header: str, rows: Sequence[tuple[str, str, str, str]], *, markdown: bool,
                  widths: tuple[int, int, int],
                  columns: tuple[str, str, str, str] = COLUMNS) -> None:
    """Prints ``header`` (nothing when empty) and ``rows``.

    ``widths``: the measure's, the result's and the ratio's in plain text; ``columns`` names
    the Markdown table's columns.
    """
    if markdown:
        if header:
            print(header + "\n")
        print("| " + " | ".join(columns) + " |\n| --- | --: | --: | --- |")
        for row in rows:
            print("| " + " | ".join(row) + " |")
        return
    if header:
        print(header)
    name_width, value_width, ratio_width = widths
    for name, value, ratio, goal in rows:
        print(f"  {name:<{name_width}} {value:>{value_width}}  {ratio:<{ratio_width}} {goal}")
