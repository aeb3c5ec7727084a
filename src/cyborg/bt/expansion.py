"""How big each tree of a project becomes once its subtree references are expanded.

The sizes are measured on the specs, before anything is built. Each use of a subtree builds its
own copy (see :mod:`cyborg.bt.builder`), so a tree that uses the next tree twice, twenty times
over, would build 2^20 copies: a million nodes, gigabytes and minutes, from a file of a few
kilobytes. :func:`measure` computes, for every tree, the number of node instances and the
levels its instance would have, in time proportional to the file (each tree is measured once,
without recursion, and counts stop growing just past the cap), so the builder can refuse a tree
that is too big before building any of it, and ``check_file`` can check a project's other trees
without expanding the same subtrees again and again.

Counting follows the builder: an instance is one node for the tree itself plus, for every node
reached from the tree's root, one node, or the whole instance of the tree it references. Levels
count the tree's own node as level 1; a reference stands where its tree's own node would. A
cycle of references, a missing child or a node with two parents is left for the builder to
report; here it just stops the count.
"""

from __future__ import annotations

from dataclasses import dataclass

from cyborg.bt.specs import ProjectSpec, TreeSpec


@dataclass(frozen=True)
class Size:
    """A tree's instance: how many nodes, and how many levels deep."""

    nodes: int
    """Node instances, at most ``cap + 1`` (larger counts are not kept)."""
    levels: int
    """Levels of the instance, the tree's own node being level 1."""


def measure(project: ProjectSpec, cap: int, root: TreeSpec | None = None) -> dict[str, Size]:
    """The :class:`Size` of every tree of ``project``, by tree id; with ``root``, of it only.

    With ``root``, the trees it references are measured too, and no others: building one tree
    of a project of many (as each mode of a mode file does) costs its own size, not the
    project's. Node counts stop at ``cap + 1``: such a count only says that the tree is too big.
    """
    trees = project.tree_by_id()
    sizes: dict[str, Size] = {}
    active: set[str] = set()  # trees being measured: a reference to one of them is a cycle
    layouts: dict[str, list[tuple[int, str | None]]] = {}
    for start in trees if root is None or root.id not in trees else [root.id]:
        stack = [start]
        while stack:
            tree_id = stack[-1]
            if tree_id in sizes:
                stack.pop()
                continue
            if tree_id not in active:  # first visit: measure what it references first
                active.add(tree_id)
                layouts[tree_id] = _layout(trees[tree_id], trees)
                waiting = [target for _, target in layouts[tree_id] if target is not None
                           and target not in sizes and target not in active]
                if waiting:
                    stack.extend(dict.fromkeys(waiting))
                    continue
            nodes, levels = 1, 1
            for level, target in layouts.pop(tree_id):
                inner = sizes.get(target) if target is not None else None
                if inner is None:  # a plain node, or a reference that closes a cycle
                    nodes, levels = nodes + 1, max(levels, level + 1)
                else:
                    nodes, levels = nodes + inner.nodes, max(levels, level + inner.levels)
                nodes = min(nodes, cap + 1)
            sizes[tree_id] = Size(nodes, levels)
            active.discard(tree_id)
            stack.pop()
    return sizes


def _layout(tree: TreeSpec, trees: dict[str, TreeSpec]) -> list[tuple[int, str | None]]:
    """Each node reached from the tree's root, once, as (level, referenced tree id).

    The root's level is 1; the tree id is ``None`` for a node that is not a reference.
    """
    if tree.root is None or tree.root not in tree.nodes:
        return []
    found: list[tuple[int, str | None]] = []
    seen = {tree.root}
    pending = [(tree.root, 1)]
    while pending:
        node_id, level = pending.pop()
        spec = tree.nodes[node_id]
        if spec.name in trees:
            found.append((level, spec.name))
            continue  # a reference's own children are an error, not part of the instance
        found.append((level, None))
        for child in spec.children:
            if child in tree.nodes and child not in seen:
                seen.add(child)
                pending.append((child, level + 1))
    return found
