"""A tree's structure JSON read back as a flat outline: every node in pre-order, with its parent.

A running tree publishes its shape once as JSON (``cyborg.bt.structure/1``, see
docs/tree-structure.md); whoever colours it with per-tick statuses needs it flat, indexed the
way the ticks name nodes (by stable id). :class:`StructureOutline` is that flat form, shared by
the web monitor (live) and the run report (from a recording)::

    outline = StructureOutline.parse(message.tree)
    outline.ids[0]              # the root's id
    outline.index_of[node_id]   # a node's pre-order index
    outline.parents[i]          # its parent's index, -1 for the root
    outline.depths[i]           # how deep it sits (the root is 0)
    outline.labels[i]           # its label (title with properties filled in), else its name

The walk is iterative: a tree as deep as a loaded tree may be (docs/tree-structure.md) is
read as safely as a flat one.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from typing import Any


class StructureError(ValueError):
    """A ``behavior_tree`` message that is not a tree structure; the message says why."""


@dataclass
class StructureOutline:
    """A tree's nodes in pre-order (the order the structure lists them); see the module."""

    structure: dict[str, Any]
    """The parsed structure, as published."""
    ids: list[str] = field(default_factory=list)
    parents: list[int] = field(default_factory=list)
    depths: list[int] = field(default_factory=list)
    labels: list[str] = field(default_factory=list)
    categories: list[str] = field(default_factory=list)
    """``composite``, ``decorator``, ``action``, ``condition``, ``tree`` ("" when not said)."""
    index_of: dict[str, int] = field(default_factory=dict)

    @classmethod
    def parse(cls, text: str) -> StructureOutline:
        """The outline of a structure's JSON text; StructureError says what is wrong."""
        try:
            structure = json.loads(text)
            root = structure["root"]
        except (ValueError, TypeError, KeyError) as exc:
            raise StructureError(f"not a tree structure: {exc}") from None
        outline = cls(structure)
        outline._index(root)
        outline.index_of = {uid: index for index, uid in enumerate(outline.ids)}
        return outline

    def _index(self, root: Any) -> None:
        stack: list[tuple[Any, int, int]] = [(root, -1, 0)]
        while stack:
            current, parent, depth = stack.pop()
            try:
                uid = str(current["id"])
                children = current.get("children", [])
            except (TypeError, KeyError, AttributeError) as exc:
                raise StructureError(f"node {len(self.ids)} has no {exc}") from None
            self.ids.append(uid)
            self.parents.append(parent)
            self.depths.append(depth)
            self.labels.append(str(current.get("label") or current.get("name") or uid))
            self.categories.append(str(current.get("category") or ""))
            index = len(self.ids) - 1
            stack.extend((child, index, depth + 1) for child in reversed(children))

    def __len__(self) -> int:
        return len(self.ids)
