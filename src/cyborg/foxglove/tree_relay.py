"""A tree runner's ticks as JSON, one message per tick, for Foxglove's panels and plots.

For each tree runner on the bus (found by its structure topic,
:func:`cyborg.interfaces.tree_runner.runner_namespace`) under its namespace ``NS``, the channel
``NS/tick`` (JSON, schema ``cyborg.TreeTick``, :data:`TICK_SCHEMA`) carries per tick::

    {"tree_id": "68f7…", "title": "Root tree", "source": "patrol.b3.json", "runner": "/cyborg/bt",
     "tick": 412, "time": 85.3, "duration_ms": 0.41, "status": "running",
     "nodes": [{"id": "68f7…", "title": "Root tree", "name": "68f7…",
                "status": "running", "ticked": true}, …],
     "active": ["68f7…", "76f0…"]}

``nodes`` lists every node of the structure in pre-order, with the status it returned in this
tick (``ticked``) or, if it did not run, the one it returned last (``idle``: never yet);
``title`` is the title as the editor shows it (placeholders filled in). ``time`` is the tick's
clock time in seconds (simulated time under ``use_sim_time``); ``duration_ms`` the tick's wall
time, null when the runner did not time it. It decodes the runner's
``behavior_tree`` structure and ``status`` messages as the contracts give them
(:mod:`cyborg.interfaces.tree_runner`); ticks of a structure it does not know yet are skipped.
"""

from __future__ import annotations

import json
import math
from typing import Any

import foxglove

from cyborg.bt.status import Status
from cyborg.bus import Node
from cyborg.bus.executor import CallbackThread
from cyborg.bus.msgs.cyborg_msgs.msg import BehaviorTree, BehaviorTreeStatus
from cyborg.foxglove.derived_relay import DerivedRelay
from cyborg.foxglove.schemas import JSON, json_schema
from cyborg.interfaces import tree_runner
from cyborg.interfaces.contract import Topic, resolve

TICK_CHANNEL = "tick"
"""The ticks' channel, under the runner's namespace."""
IDLE = "idle"
"""The status of a node that has not run since the structure came."""
_NODE: dict[str, Any] = {"type": "object", "properties": {
    "id": {"type": "string"}, "title": {"type": "string"}, "name": {"type": "string"},
    "status": {"enum": [IDLE, *(status.label for status in Status)]},
    "ticked": {"type": "boolean"}}, "required": ["id", "title", "status", "ticked"]}
TICK_SCHEMA: dict[str, Any] = {
    "$schema": "https://json-schema.org/draft/2020-12/schema",
    "title": "cyborg.TreeTick", "type": "object",
    "properties": {
        "tree_id": {"type": "string"}, "title": {"type": "string"},
        "source": {"type": "string"}, "runner": {"type": "string"},
        "tick": {"type": "integer"}, "time": {"type": "number"},
        "duration_ms": {"type": ["number", "null"]}, "status": _NODE["properties"]["status"],
        "nodes": {"type": "array", "items": _NODE},
        "active": {"type": "array", "items": {"type": "string"}}},
    "required": ["tree_id", "title", "tick", "time", "status", "nodes"]}
"""The JSON Schema of one tick's message."""


def status_label(code: int) -> str:
    """``"success"`` for 1 and so on, as the engine names statuses; ``"idle"`` for others."""
    try:
        return Status(code).label
    except ValueError:
        return IDLE


def structure_nodes(text: str) -> tuple[dict[str, Any], list[dict[str, str]]]:
    """The structure's header fields and its nodes in pre-order; ValueError if not a tree."""
    try:
        structure = json.loads(text)
        root = structure["root"]
    except (ValueError, TypeError, KeyError) as exc:
        raise ValueError(f"behavior_tree is not a tree structure: {exc}") from None
    header = {"tree_id": str(structure.get("tree_id", "")),
              "title": str(structure.get("title", "")),
              "source": str(structure.get("source", ""))}
    nodes: list[dict[str, str]] = []
    stack = [root]
    while stack:  # no recursion: a structure nests hundreds of levels deep
        node = stack.pop()
        if not isinstance(node, dict) or "id" not in node:
            raise ValueError(f"behavior_tree: node {len(nodes)} has no id")
        nodes.append({"id": str(node["id"]),
                      "title": str(node.get("label") or node.get("title") or node.get("name")
                                   or ""),
                      "name": str(node.get("name", ""))})
        stack.extend(reversed(node.get("children") or []))
    return header, nodes


class TreeTickRelay(DerivedRelay):
    """A tree runner's ticks on ``NS/tick`` as JSON (see the module's description)."""

    def __init__(self, node: Node, namespace: str, thread: CallbackThread,
                 context: foxglove.Context) -> None:
        super().__init__(resolve(namespace, TICK_CHANNEL), node, namespace,
                         (tree_runner.STRUCTURE, tree_runner.STATUS), thread)
        self.channel: foxglove.Channel = foxglove.Channel(
            self.topic, schema=json_schema("cyborg.TreeTick", TICK_SCHEMA),
            message_encoding=JSON, context=context)
        self._header: dict[str, Any] | None = None
        self._nodes: list[dict[str, str]] = []
        self._index: dict[str, int] = {}
        self._last: list[str] = []

    def close(self) -> None:
        """Leave the bus and forget the structure."""
        super().close()
        self._header = None

    def convert(self, source: Topic[Any], message: Any) -> bytes | None:
        """A structure is kept (nothing written); a tick becomes its JSON."""
        if isinstance(message, BehaviorTree):
            self._header, self._nodes = structure_nodes(message.tree)
            self._index = {node["id"]: index for index, node in enumerate(self._nodes)}
            self._last = [IDLE] * len(self._nodes)
            return None
        if self._header is None or not isinstance(message, BehaviorTreeStatus):
            return None
        return json.dumps(self._tick(message)).encode("utf-8")

    def _tick(self, message: BehaviorTreeStatus) -> dict[str, Any]:
        ticked = [False] * len(self._nodes)
        for uid, code in zip(message.visited_ids, message.visited_statuses, strict=False):
            index = self._index.get(uid)
            if index is not None:
                self._last[index] = status_label(int(code))
                ticked[index] = True
        stamp, duration = message.stamp, float(message.duration)
        return {**(self._header or {}), "runner": self.namespace, "tick": int(message.tick),
                "time": stamp.sec + stamp.nanosec * 1e-9,
                "duration_ms": duration * 1000.0 if math.isfinite(duration) else None,
                "status": status_label(int(message.status)),
                "nodes": [{**node, "status": status, "ticked": fresh} for node, status, fresh
                          in zip(self._nodes, self._last, ticked, strict=True)],
                "active": list(message.active_ids)}

    def write(self, result: bytes, log_time: int) -> None:
        """Log one tick's JSON."""
        self.channel.log(result, log_time=log_time)
