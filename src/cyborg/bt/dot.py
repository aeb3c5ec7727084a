"""Graphviz DOT export of a tree structure.

Nodes are drawn top-down with siblings left to right in tick order, shaped by category
(composites as boxes, decorators as hexagons, actions as rounded boxes, conditions as
ellipses), and each subtree instance is a labelled cluster. Pass ``statuses`` (node id ->
status name) to colour a tick's result, and ``active`` to draw the running path as rqt_bt did:
active nodes outlined in green, the edges between them dashed red. ``collapsed`` ids are drawn
as one node standing for their whole subtree ("+N" nodes hidden), which is how a monitor
exports what it shows; ``rankdir="LR"`` lays a wide tree out left to right, siblings then
running top to bottom. A composite carrying services names them, with their intervals, on a
second line of its label.
"""

from __future__ import annotations

import re
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
_SURROGATE = re.compile("[\ud800-\udfff]")


def quote(text: str) -> str:
    """``text`` as a DOT double-quoted string, escaped.

    A lone surrogate (not a character, and not writable as UTF-8) becomes U+FFFD, so the output
    can always be written.
    """
    if not text.isascii():
        text = _SURROGATE.sub("\ufffd", text)
    escaped = text.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n")
    return f'"{escaped}"'


def structure_to_dot(structure: Mapping[str, Any], *,
                     statuses: Mapping[str, str] | None = None,
                     active: Iterable[str] = (), collapsed: Iterable[str] = (),
                     rankdir: str = "TB", graph_attributes: str = "") -> str:
    """DOT text for a structure as returned by ``TreeStructure.to_json()``."""
    statuses = statuses or {}
    active_ids = set(active)
    folded = set(collapsed)
    if rankdir not in ("TB", "LR"):
        raise ValueError(f"rankdir must be TB or LR, not {rankdir!r}")
    extra = f", {graph_attributes}" if graph_attributes else ""
    lines = [
        f"digraph {quote(structure.get('title') or 'behaviour tree')} {{",
        f'  graph [rankdir={rankdir}, ordering=out, fontname="Helvetica"{extra}];',
        '  node [fontname="Helvetica", fontsize=11];',
        '  edge [arrowsize=0.6];',
    ]
    cluster = 0
    # Written with a stack of things still to write instead of recursion, so a structure of
    # any depth can be exported. An entry is a node to draw, a sibling cluster to open, or a
    # finished line; a node's entries are pushed in reverse, to come off in writing order.
    pending: list[tuple[str, Any, str]] = [("node", structure["root"], "    ")]
    lines.append('  subgraph cluster_0 { label=""; peripheries=0;')  # nesting alike at all depths
    while pending:
        kind, item, indent = pending.pop()
        if kind == "line":
            lines.append(item)
            continue
        if kind == "cluster":  # numbered when opened, so numbers follow the writing order
            cluster += 1
            lines.append(f"{indent}subgraph cluster_{cluster} {{")
            lines.append(f"{indent}  {item}")
            continue
        node: Mapping[str, Any] = item
        uid = node["id"]
        label = (node["label"] or node["name"]) + _services_line(node.get("services"))
        children = node.get("children", [])
        attributes = _SHAPES.get(node["category"], "shape=box")
        if uid in folded and children:
            label += f"\n(+{_count(node) - 1})"
            attributes = attributes.replace('style="', 'peripheries=2, style="')
            children = []
        fill = _FILL.get(statuses.get(uid, ""), _IDLE)
        bold = ', color="#188038", penwidth=3' if uid in active_ids else ""
        lines.append(f"{indent}{quote(uid)} [label={quote(label)}, {attributes}, "
                     f"fillcolor={quote(fill)}{bold}];")
        later: list[tuple[str, Any, str]] = []
        # ordering=out alone lets Graphviz swap siblings once clusters are involved; a cluster
        # per sibling (invisible unless it is a subtree instance) keeps them in tick order. A
        # left-to-right drawing stacks sibling clusters bottom-up, so they are written reversed.
        for child in (children[::-1] if rankdir == "LR" else children):
            subtree = child["category"] == "tree" and child.get("children")
            if subtree or len(children) > 1:
                frame = (f'label={quote(child["label"])}; style=dashed; color="#9aa0a6"; '
                         "peripheries=1;" if subtree else 'label=""; peripheries=0;')
                later += [("cluster", frame, indent), ("node", child, indent + "  "),
                          ("line", f"{indent}}}", "")]
            else:
                later.append(("node", child, indent))
        for child in children:
            edge_bold = (' [color="#d93025", style=dashed, penwidth=2]'
                         if uid in active_ids and child["id"] in active_ids else "")
            later.append(("line", f"{indent}{quote(uid)} -> {quote(child['id'])}{edge_bold};",
                          ""))
        pending.extend(reversed(later))
    lines.append("  }")
    lines.append("}")
    return "\n".join(lines) + "\n"


def _services_line(services: Any) -> str:
    """A composite's services as a second line of its label: ``⟳ BatteryWatch 1s, ClosestGoal 2s``.

    Empty for a node without any, or with a malformed list (a structure from elsewhere).
    """
    if not isinstance(services, list):
        return ""
    named = []
    for entry in services:
        if isinstance(entry, dict) and isinstance(entry.get("name"), str):
            interval = entry.get("interval")
            every = f" {interval:g}s" if isinstance(interval, int | float) else ""
            named.append(entry["name"] + every)
    return "\n\u27f3 " + ", ".join(named) if named else ""


def _count(node: Mapping[str, Any]) -> int:
    """Nodes in ``node``'s subtree, itself included (counted without recursion)."""
    count, pending = 0, [node]
    while pending:
        count += 1
        pending.extend(pending.pop().get("children", []))
    return count
