"""Per-node control of a running tree: disable a subtree, force a result, breakpoints, step.

One hook model covers what a monitor needs (Groot2 calls these hooks too)::

    hooks = tree.hooks
    hooks.disable("a3f…", FAILURE)        # the node's subtree is not ticked; it returns FAILURE
    hooks.force("b71…", SUCCESS, once=True)  # the node ticks, its result is replaced, once
    hooks.breakpoint("c09…")              # the tick stops before the node ticks …
    hooks.paused_at                       # … "c09…", until
    hooks.resume()                        # the tick goes on (hooks.step(): stop at the next node)
    hooks.clear("a3f…")                   # back to normal

* **Disable** (a "pre, replace" hook): the node is not ticked, nor anything below it; it returns
  the chosen status (SUCCESS or FAILURE). A RUNNING subtree is halted when it is disabled, so an
  action below it cancels what it started.
* **Force**: the node ticks as usual and its result is replaced (fault injection). With
  ``once`` the hook goes away after one use.
* **Breakpoint**: the ticking thread waits before the node ticks until :meth:`TreeHooks.resume`,
  :meth:`TreeHooks.step` or :meth:`TreeHooks.release`. :meth:`TreeHooks.step` lets the tick go on
  to the next node about to tick and stops there.

Every hook has an ``owner`` (a name chosen by whoever set it, e.g. the monitor's bus identity);
:meth:`TreeHooks.clear_owner` removes all of an owner's hooks when it goes away. Hooks are keyed
by node id, so they survive a reload of the same tree.

**How.** Hooks work through the node's own extension points, as BehaviorTree.CPP's Groot2
publisher does: a hooked node's :attr:`~cyborg.bt.node.Node.pre_tick` slot waits at a
breakpoint or substitutes the disabled status, its :attr:`~cyborg.bt.node.Node.post_tick` slot
replaces a forced result. Callbacks a node already had stay in force behind the hook and are
back in their slots when it is cleared. Nothing else of the node changes; a node without hooks
has empty slots and ticks at full speed. While a tick is stepped, every node gets the pre-tick
slot, so that the next one about to tick stops.

**Timing** is not a hook: it is an option of the tree, :attr:`Tree.timing
<cyborg.bt.tree.Tree.timing>`, applied between ticks (``hooks.timing`` is kept as another name
for it).
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from enum import StrEnum
from time import perf_counter
from typing import TYPE_CHECKING

from cyborg.bt.status import FAILURE, RUNNING, SUCCESS, Status

if TYPE_CHECKING:
    from cyborg.bt.node import Node, PostTick, PreTick
    from cyborg.bt.tree import Tree


class HookMode(StrEnum):
    """What a :class:`Hook` does at its node: see the module docstring."""

    DISABLE = "disable"
    FORCE = "force"
    BREAKPOINT = "breakpoint"


@dataclass(frozen=True)
class Hook:
    """What to do at one node."""

    node: str
    """The node's id (its ``uid``)."""
    mode: HookMode
    status: Status = SUCCESS
    """The status a disabled node returns, or a forced node's result."""
    once: bool = False
    """Whether the hook goes away after its first use (force and breakpoint)."""
    owner: str = ""
    """Who set it; :meth:`TreeHooks.clear_owner` removes an owner's hooks."""


ALLOWED = {
    HookMode.DISABLE: (SUCCESS, FAILURE),
    HookMode.FORCE: (SUCCESS, FAILURE, RUNNING),
    HookMode.BREAKPOINT: (SUCCESS, FAILURE, RUNNING),
}


class HookError(ValueError):
    """A hook that cannot be set; the message names the node and the reason."""


class TreeHooks:
    """The hooks of one tree (``tree.hooks``); safe to change from any thread."""

    def __init__(self, nodes: Iterable[Node], tree: Tree | None = None) -> None:
        self._nodes = {node.uid: node for node in nodes}
        self._tree = tree
        self._hooks: dict[str, Hook] = {}
        self._held: dict[str, tuple[PreTick | None, PostTick | None]] = {}
        """Node id -> the callbacks its slots had before this object took them."""
        self._lock = threading.Condition()
        self._released = 0  # bumped to let waiting ticks go on
        self.stepping = False
        self.waited = 0.0
        """Seconds ticks have spent waiting at breakpoints."""
        self.paused_at: str | None = None
        """Id of the node a tick is waiting before, or None."""
        self.listeners: list[Callable[[], None]] = []
        """Called (from the thread that made the change) whenever hooks or the pause change."""

    # ------------------------------------------------------------------ setting
    def set(self, hook: Hook) -> None:
        """Sets (or replaces) the hook of ``hook.node``; :class:`HookError` if it cannot be."""
        node = self._nodes.get(hook.node)
        if node is None:
            raise HookError(f"no node with id {hook.node!r} in the tree")
        if hook.status not in ALLOWED[hook.mode]:
            allowed = " or ".join(status.label for status in ALLOWED[hook.mode])
            raise HookError(f"node {hook.node}: a {hook.mode.value} hook returns {allowed}, "
                            f"not {hook.status.label}")
        with self._lock:
            self._hooks[hook.node] = hook
            self._attach(node)
        self._changed()

    def disable(self, uid: str, status: Status = FAILURE, *, owner: str = "") -> None:
        """Disables node ``uid``: it returns ``status`` (SUCCESS or FAILURE) without ticking.

        Nothing below it ticks either, and a RUNNING subtree is halted. Raises
        :class:`HookError` as :meth:`set` does.
        """
        self.set(Hook(uid, HookMode.DISABLE, status, owner=owner))

    def force(self, uid: str, status: Status, *, once: bool = False, owner: str = "") -> None:
        """Makes ``status`` the result of node ``uid`` each time it has ticked as usual.

        With ``once`` the hook goes away after its first use. Raises :class:`HookError` as
        :meth:`set` does.
        """
        self.set(Hook(uid, HookMode.FORCE, status, once=once, owner=owner))

    def breakpoint(self, uid: str, *, once: bool = False, owner: str = "") -> None:
        """Makes the ticking thread wait before node ``uid`` ticks, until let go.

        :meth:`resume`, :meth:`step` and :meth:`release` let it go; with ``once`` the
        breakpoint goes away after it was hit. Raises :class:`HookError` as :meth:`set` does.
        """
        self.set(Hook(uid, HookMode.BREAKPOINT, once=once, owner=owner))

    def clear(self, uid: str) -> bool:
        """Removes the hook of node ``uid`` (a tick waiting there goes on); False if none."""
        with self._lock:
            hook = self._hooks.pop(uid, None)
            if hook is None:
                return False
            self._attach(self._nodes[uid])
            if self.paused_at == uid and not self.stepping:
                self._release_locked()
        self._changed()
        return True

    def clear_owner(self, owner: str) -> list[str]:
        """Removes every hook set by ``owner``; returns the node ids that had one."""
        ids = [uid for uid, hook in list(self._hooks.items()) if hook.owner == owner]
        for uid in ids:
            self.clear(uid)
        return ids

    def clear_all(self) -> None:
        """Removes every hook and lets any waiting tick run to its end."""
        for uid in list(self._hooks):
            self.clear(uid)
        self.release()

    # ------------------------------------------------------------------ reading
    def hooks(self) -> list[Hook]:
        """Every hook set, in tree order."""
        order = {uid: index for index, uid in enumerate(self._nodes)}
        return sorted(self._hooks.values(), key=lambda hook: order[hook.node])

    def get(self, uid: str) -> Hook | None:
        """The hook of node ``uid``, or ``None``."""
        return self._hooks.get(uid)

    # ------------------------------------------------------------------ timing
    @property
    def timing(self) -> bool:
        """Another name for :attr:`Tree.timing <cyborg.bt.tree.Tree.timing>`.

        It is applied between ticks. Hooks made without a tree read False, and setting it
        raises :class:`RuntimeError`.
        """
        return self._tree is not None and self._tree.timing

    @timing.setter
    def timing(self, on: bool) -> None:
        if self._tree is None:
            raise RuntimeError("these hooks belong to no tree: set Tree.timing instead")
        self._tree.timing = on

    # ------------------------------------------------------------------ the nodes' slots
    def before_tick(self, node: Node) -> Status | None:
        """The pre-tick callback of a hooked node, called in the ticking thread.

        Waits at a breakpoint (or while stepping), then returns the status of a disabled node,
        else what the node's own callback says.
        """
        hook = self._hooks.get(node.uid)
        if self.stepping or (hook is not None and hook.mode is HookMode.BREAKPOINT):
            self.wait_at(node, hook)
        if hook is not None and hook.mode is HookMode.DISABLE:
            return hook.status
        held = self._held.get(node.uid)
        return None if held is None or held[0] is None else held[0](node)

    def after_tick(self, node: Node, status: Status) -> Status | None:
        """The post-tick callback of a hooked node: its own callback, then a forced result.

        A ``once`` hook goes away here.
        """
        held = self._held.get(node.uid)
        if held is not None and held[1] is not None:
            replaced = held[1](node, status)
            if replaced is not None:
                status = replaced
        hook = self._hooks.get(node.uid)
        if hook is None or hook.mode is not HookMode.FORCE:
            return status
        if hook.once:
            self.clear(hook.node)
        return hook.status

    # ------------------------------------------------------------------ pausing
    def wait_at(self, node: Node, hook: Hook | None) -> None:
        """Called in the ticking thread: waits before ``node`` until released."""
        started = perf_counter()
        with self._lock:
            if self.stepping:
                self.stepping = False
                self._detach_steps()
            ticket = self._released
            self.paused_at = node.uid
        self._changed()
        with self._lock:
            while self._released == ticket:
                self._lock.wait()
            self.paused_at = None
            self.waited += perf_counter() - started
        if hook is not None and hook.once and hook.mode is HookMode.BREAKPOINT:
            self.clear(hook.node)
        self._changed()

    def resume(self) -> bool:
        """Lets a tick waiting at a breakpoint go on; False if none was waiting."""
        with self._lock:
            waiting = self.paused_at is not None
            self._release_locked()
        return waiting

    def step(self) -> bool:
        """Lets a waiting tick go on to the next node about to tick, and stops it there.

        False (and nothing happens) when no tick is waiting.
        """
        with self._lock:
            if self.paused_at is None:
                return False
            self.stepping = True
            for node in self._nodes.values():
                self._attach(node)
            self._release_locked()
        return True

    def release(self) -> None:
        """Lets any waiting tick run to its end (used when the runner pauses or stops)."""
        with self._lock:
            if self.stepping:
                self.stepping = False
                self._detach_steps()
            self._release_locked()

    # ------------------------------------------------------------------ moving to a new tree
    def carry_to(self, other: TreeHooks) -> list[str]:
        """Sets this tree's hooks on ``other``; returns the node ids of those dropped.

        A hook is dropped where ``other`` has no node of its id (after a reload).
        """
        dropped = []
        for hook in self.hooks():
            try:
                other.set(hook)  # hooks are frozen: the same one can serve both trees
            except HookError:
                dropped.append(hook.node)
        return dropped

    # ------------------------------------------------------------------ internals
    def _attach(self, node: Node) -> None:
        """Takes ``node``'s slots if it is hooked or a tick is stepped; gives them back if not."""
        uid = node.uid
        wanted = self.stepping or uid in self._hooks
        if wanted and uid not in self._held:
            self._held[uid] = (node.pre_tick, node.post_tick)
            node.pre_tick, node.post_tick = self.before_tick, self.after_tick
        elif not wanted and uid in self._held:
            node.pre_tick, node.post_tick = self._held.pop(uid)

    def _detach_steps(self) -> None:
        for uid in list(self._held):
            if uid not in self._hooks:
                self._attach(self._nodes[uid])

    def _release_locked(self) -> None:
        self._released += 1
        self._lock.notify_all()

    def _changed(self) -> None:
        for listener in list(self.listeners):
            listener()
