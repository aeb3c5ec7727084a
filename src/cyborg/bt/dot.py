"""Graphviz DOT export of a tree structure.

Nodes are drawn top-down in child order, shaped by category (composites as boxes, decorators as
hexagons, actions as rounded boxes, conditions as ellipses) and each subtree instance is a
labelled cluster. Pass ``statuses`` (node id -> status name) to colour a tick's result, and
``active`` to draw the running path in bold.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any

_SHAPES = {
    "composite": 'shape=box, style="filled"',
    "decorator": 'shape=hexagon, style="filled"',
    "action": 'shape=box, style="rounded,filled"',
    "condition": 'shape=ellipse, style="filled"',
    "tree": 'shape=folder, style="filled"',
}
_FILL = {"success": "#8fd18f", "failure": "#f28b82", "running": "#fdd663", "error": "#c58af9"}
_IDLE = "#f1f3f4"


def quote(text: str) -> str:
    """A DOT double-quoted string."""
    escaped = text.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n")
    return f'"{escaped}"'


def structure_to_dot(structure: Mapping[str, Any], *,
                     statuses: Mapping[str, str] | None = None,
                     active: Iterable[str] = ()) -> str:
    """DOT text for a structure as returned by ``TreeStructure.to_json()``."""
    statuses = statuses or {}
    active_ids = set(active)
    lines = [
        f"digraph {quote(structure.get('title') or 'behaviour tree')} {{",
        '  graph [rankdir=TB, ordering=out, fontname="Helvetica"];',
        '  node [fontname="Helvetica", fontsize=11];',
        '  edge [arrowsize=0.6];',
    ]
    cluster = [0]

    def emit(node: Mapping[str, Any], indent: str) -> None:
        uid = node["id"]
        label = node["label"] or node["name"]
        attributes = _SHAPES.get(node["category"], "shape=box")
        fill = _FILL.get(statuses.get(uid, ""), _IDLE)
        bold = ", penwidth=3" if uid in active_ids else ""
        lines.append(f"{indent}{quote(uid)} [label={quote(label)}, {attributes}, "
                     f"fillcolor={quote(fill)}{bold}];")
        children = node.get("children", [])
        for child in children:
            if child["category"] == "tree" and child.get("children"):
                cluster[0] += 1
                lines.append(f"{indent}subgraph cluster_{cluster[0]} {{")
                lines.append(f"{indent}  label={quote(child['label'])}; style=dashed; "
                             'color="#9aa0a6";')
                emit(child, indent + "  ")
                lines.append(f"{indent}}}")
            else:
                emit(child, indent)
        for child in children:
            edge_bold = " [penwidth=3]" if uid in active_ids and child["id"] in active_ids else ""
            lines.append(f"{indent}{quote(uid)} -> {quote(child['id'])}{edge_bold};")

    emit(structure["root"], "  ")
    lines.append("}")
    return "\n".join(lines) + "\n"
