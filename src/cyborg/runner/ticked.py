"""What a tree runner ticks: one tree, or the machine of a mode file and its trees.

A runner of a mode file ticks a :class:`~cyborg.modes.ModeMachine`; its listeners get each
tick's snapshot after the machine may already have switched to the next mode. These functions
answer, for such a snapshot, which mode and which tree made it, and say in a few words what a
runner runs.
"""

from __future__ import annotations

from cyborg.bt.snapshot import TickSnapshot
from cyborg.bt.tree import Tree
from cyborg.modes import ModeMachine

Ticked = Tree | ModeMachine
"""What a runner ticks."""


def mode_of(ticked: Ticked, snapshot: TickSnapshot) -> str:
    """The mode whose tree made ``snapshot`` (a tick listener's); empty for a plain tree."""
    if not isinstance(ticked, ModeMachine):
        return ""
    last = ticked.last  # set by the tick that made the snapshot, before the listeners
    return last.mode if last is not None and last.snapshot is snapshot else ticked.mode


def tree_of(ticked: Ticked, snapshot: TickSnapshot) -> Tree:
    """The tree that made ``snapshot`` (a tick listener's).

    After a transition that tick led to, the machine's current tree is already the next mode's.
    """
    if not isinstance(ticked, ModeMachine):
        return ticked
    return ticked.trees.get(mode_of(ticked, snapshot), ticked.tree)


def describe(ticked: Ticked) -> str:
    """``'Root tree' (18 nodes)``, or ``4 modes, in 'normal' ('Patrol', 12 nodes)``."""
    if isinstance(ticked, ModeMachine):
        tree = ticked.tree
        return (f"{len(ticked.trees)} modes, in {ticked.mode!r} ({tree.title!r}, "
                f"{len(tree)} nodes)")
    return f"{ticked.title!r} ({len(ticked)} nodes)"
