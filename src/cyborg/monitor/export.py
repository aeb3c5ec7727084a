"""Save what the page shows as DOT, SVG or PNG, drawn by Graphviz on the server.

The page sends which nodes it shows collapsed (its draw depth and the nodes folded by hand,
with the running path already unfolded); the export draws exactly that, with the latest
statuses and the active path as rqt_bt drew it (green outline, dashed red edges).

Large trees stay usable: past :data:`WIDE_LEAVES` visible leaves the graph is laid out left to
right with compact rows (a 1,000-node tree is ~45,000 px wide top-down, and one row per leaf
left to right), and PNGs are capped at :data:`MAX_PNG_PIXELS` on their longer side, below
Graphviz's cairo limit of 32,767 px, so Graphviz never has to shrink a picture it cannot render
and every label stays legible (at least :data:`MIN_PX_PER_LEAF` pixels per row).
"""

from __future__ import annotations

import re
import shutil
import subprocess
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

from cyborg.bt.dot import structure_to_dot

FORMATS = {"dot": "text/vnd.graphviz", "svg": "image/svg+xml", "png": "image/png"}
WIDE_LEAVES = 60
MAX_PNG_PIXELS = 32000
MIN_PX_PER_LEAF = 20
PNG_DPI = 96
TIMEOUT = 60.0


class ExportError(RuntimeError):
    """An export that could not be made; the message says why."""


@dataclass(frozen=True)
class Export:
    """A finished export: its bytes, their media type, and the file name to save them under."""

    content: bytes
    media_type: str
    filename: str


def visible_leaves(node: dict[str, Any], collapsed: set[str]) -> int:
    """Leaves drawn under ``node`` (a structure's node) when the ids in ``collapsed`` are folded.

    A folded node counts as one leaf.
    """
    children = node.get("children", [])
    if not children or node["id"] in collapsed:
        return 1
    return sum(visible_leaves(child, collapsed) for child in children)


def view_dot(structure: dict[str, Any], *, statuses: dict[str, str], active: Iterable[str],
             collapsed: Iterable[str]) -> str:
    """DOT text of the view: the structure with ``collapsed`` subtrees folded."""
    folded = set(collapsed)
    wide = visible_leaves(structure["root"], folded) > WIDE_LEAVES
    inches = MAX_PNG_PIXELS / PNG_DPI
    attributes = f'size="{inches:g},{inches:g}"'
    if wide:
        attributes += ", nodesep=0.08, ranksep=0.4"
    text = structure_to_dot(structure, statuses=statuses, active=active, collapsed=folded,
                            rankdir="LR" if wide else "TB", graph_attributes=attributes)
    return text.replace("  node [", "  node [height=0.3, ", 1) if wide else text


def render(dot_text: str, file_format: str, title: str) -> Export:
    """The view in ``file_format`` (dot, svg or png); :class:`ExportError` if it cannot be."""
    if file_format not in FORMATS:
        raise ExportError(f"unknown format {file_format!r}; expected one of "
                          f"{', '.join(FORMATS)}")
    stem = re.sub(r"[^A-Za-z0-9_.-]+", "_", title).strip("_") or "behaviour_tree"
    filename = f"{stem}.{file_format}"
    if file_format == "dot":
        return Export(dot_text.encode(), FORMATS["dot"], filename)
    dot = shutil.which("dot")
    if dot is None:
        raise ExportError("Graphviz is not installed: 'dot' was not found on PATH "
                          "(Debian: apt install graphviz)")
    command = [dot, f"-T{file_format}"]
    if file_format == "png":
        command.append(f"-Gdpi={PNG_DPI}")
    try:
        result = subprocess.run(command, input=dot_text.encode(), capture_output=True,
                                timeout=TIMEOUT, check=False)
    except subprocess.TimeoutExpired:
        raise ExportError(f"Graphviz took longer than {TIMEOUT:g} s") from None
    if result.returncode != 0 or not result.stdout:
        raise ExportError(f"Graphviz failed: {result.stderr.decode(errors='replace').strip()}")
    return Export(result.stdout, FORMATS[file_format], filename)
